# Plots reference strands (from `cargo run --release -p hairloom-core --example dump_strands`)
# of the bundled samples over their bodies: a CPU preview of what the GPU will draw.
# Usage: python3 docs/plot_strands.py DUMP_DIR OUT.png   (needs matplotlib)
import json, sys
import matplotlib; matplotlib.use('Agg')
import matplotlib.pyplot as plt
from matplotlib.collections import LineCollection
dump, out = sys.argv[1], sys.argv[2]
names = ['head_short_straight', 'head_long_wavy', 'head_curly', 'teapot_fur']
fig, axes = plt.subplots(1, 4, figsize=(20, 6), facecolor='white')
for ax, name in zip(axes, names):
    body = json.load(open(f'assets/samples/{name}.hairloom'))['document']['body']['positions']
    ax.scatter([p[2] for p in body], [p[1] for p in body], s=0.3, c='#c8c8c8')
    lines = []
    for row in open(f'{dump}/{name}.txt'):
        v = [float(x) for x in row.split()]
        pts = [(v[i + 2], v[i + 1]) for i in range(0, len(v), 3)]
        lines.append(pts)
    ax.add_collection(LineCollection(lines, linewidths=0.25, colors='#5a3418', alpha=0.8))
    ax.set_aspect('equal'); ax.set_title(name.replace('_', ' ')); ax.axis('off')
    ax.autoscale()
plt.tight_layout(); plt.savefig(out, dpi=60)
