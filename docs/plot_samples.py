# Plots the hair-mesh columns of the bundled samples over their bodies (side and front).
# Run from the repository root: python3 docs/plot_samples.py  (needs matplotlib).
import json, sys
import matplotlib; matplotlib.use('Agg')
import matplotlib.pyplot as plt
names = ['head_short_straight','head_long_wavy','head_curly','teapot_fur']
fig, axes = plt.subplots(2, 4, figsize=(20, 10))
for i, n in enumerate(names):
    d = json.load(open(f'assets/samples/{n}.hairloom'))['document']
    body = d['body']['positions']
    cols = d['hair_mesh']['columns']
    for row, (a, b, lab) in enumerate([(2, 1, 'side (z,y)'), (0, 1, 'front (x,y)')]):
        ax = axes[row][i]
        ax.scatter([p[a] for p in body], [p[b] for p in body], s=0.2, c='#bbb')
        for c in cols:
            ps = c['positions']
            ax.plot([p[a] for p in ps], [p[b] for p in ps], lw=0.4, c='brown')
        ax.scatter([c['positions'][0][a] for c in cols], [c['positions'][0][b] for c in cols], s=1, c='blue')
        ax.set_aspect('equal'); ax.set_title(f'{n} {lab}')
plt.tight_layout(); plt.savefig('docs/sample_hair_meshes.png', dpi=55)
