//! The worked example of `docs/runtime-format.md` ("Worked example"): one bundle, one
//! strand, every intermediate value. Two checks:
//!
//! 1. The numbers printed in the document are what our code computes. The document's
//!    generated region (between the `example-values` markers) is rebuilt here from the
//!    public core API and compared number by number, each to the precision it is printed
//!    with. On a mismatch the test prints the region as it should read: paste it over the
//!    old one (and check the prose around it still holds).
//! 2. An implementation written from the document's formulas alone (`from_the_document`
//!    below, f32 like the shader) reproduces the CPU mirror of `strand_gen.wgsl` on this
//!    example, every strand of the bundle, within the document's tolerance for exact
//!    filtering (10⁻⁵ × model size).
//!
//! The styling parameters are read from the document's `example-styling` JSON block, so the
//! document and the test use one set.

use glam::{DVec2, DVec3, Vec2, Vec3};
use hairloom_core::Document;
use hairloom_core::geometry::curve::{cubic_to_quadratics, curve_segments};
use hairloom_core::io::runtime_bundle::{Manifest, bundle_files, load_runtime_asset_from};
use hairloom_core::model::mesh::HairMesh;
use hairloom_core::model::root_maps::RootMapChannel;
use hairloom_core::model::styling::StylingParams;
use hairloom_core::runtime::atlas::{Atlas, BundleBlock};
use hairloom_core::runtime::hair::{RuntimeHair, RuntimeOptions, sample_rank, strand_root};
use hairloom_core::runtime::strand_gen::{Filtering, StrandGen, fetch};
use hairloom_core::runtime::textures::Precision;
use hairloom_core::strands::lod::{morph_odd_vertices, strand_count, thickness_factor, vertex_lod};
use hairloom_core::strands::random::{hash_to_unit, hash_values, pcg_hash};
use hairloom_core::strands::styling::{
    StrandStyling, StylingInput, clump_pull, clump_pull_on, lock_phase, strand_cell_random,
    strand_length_fraction, strand_random, styling_offset, twist, value_noise_1d,
};

const DOC: &str = include_str!("../../docs/runtime-format.md");
const BEGIN: &str = "<!-- example-values:begin";
const END: &str = "<!-- example-values:end -->";
/// Vertices per strand in the example (2^3 + 1).
const VERTICES: usize = 9;
/// The vertices the per-vertex table shows.
const SHOWN: [usize; 4] = [1, 3, 6, 8];

/// The example's hair mesh: one quad bundle of two layers; four columns leaning apart.
fn example_document(styling: &StylingParams) -> Document {
    let columns = [
        [[0.0, 0.0, 0.0], [0.0, -0.04, 0.01], [0.002, -0.08, 0.03]],
        [
            [0.01, 0.0, 0.0],
            [0.011, -0.041, 0.008],
            [0.014, -0.079, 0.024],
        ],
        [
            [0.01, 0.0, 0.01],
            [0.012, -0.039, 0.021],
            [0.016, -0.078, 0.042],
        ],
        [
            [0.0, 0.0, 0.01],
            [-0.001, -0.04, 0.02],
            [-0.002, -0.081, 0.04],
        ],
    ];
    let roots: Vec<DVec3> = columns.iter().map(|c| DVec3::from_array(c[0])).collect();
    let uvs = [[0.4, 0.7], [0.45, 0.7], [0.45, 0.75], [0.4, 0.75]].map(DVec2::from_array);
    let mut mesh = HairMesh::from_scalp(&roots, &[vec![0, 1, 2, 3]], &[uvs.to_vec()]);
    for (column, points) in mesh.columns.iter_mut().zip(&columns) {
        column.positions = points.iter().map(|p| DVec3::from_array(*p)).collect();
    }
    mesh.bundles[0].layers = 2;
    mesh.update_w();
    let mut document = Document::new("runtime-format example", mesh);
    document.styling.global = styling.clone();
    document.validate().expect("the example document is valid");
    document
}

fn example_hair(document: &Document) -> RuntimeHair {
    RuntimeHair::from_document(
        document,
        &RuntimeOptions {
            precision: Precision::F32,
            ..RuntimeOptions::default()
        },
    )
}

/// The styling JSON of the document's `example-styling` block.
fn documented_styling() -> StylingParams {
    let start = DOC
        .find("<!-- example-styling -->")
        .expect("docs/runtime-format.md has an <!-- example-styling --> marker");
    let rest = &DOC[start..];
    let open = rest
        .find("```json")
        .expect("a ```json block follows the marker")
        + 7;
    let close = rest[open..].find("```").expect("the block is closed") + open;
    serde_json::from_str(&rest[open..close]).expect("the example styling parses")
}

// ---------------------------------------------------------------------------------------
// The generated region: tables of (quantity, printed values).

struct Table {
    caption: String,
    header: Vec<String>,
    rows: Vec<(String, Vec<String>)>,
}

impl Table {
    fn new(caption: &str, header: &[&str]) -> Self {
        Self {
            caption: caption.into(),
            header: header.iter().map(|h| h.to_string()).collect(),
            rows: Vec::new(),
        }
    }

    fn row(&mut self, key: &str, cells: Vec<String>) {
        self.rows.push((key.into(), cells));
    }
}

fn fixed(values: &[f64], decimals: usize) -> String {
    values
        .iter()
        .map(|v| {
            let text = format!("{v:.decimals$}");
            // No "-0.000": a reader compares signs too.
            if text
                .trim_start_matches('-')
                .chars()
                .all(|c| c == '0' || c == '.')
            {
                text.trim_start_matches('-').to_string()
            } else {
                text
            }
        })
        .collect::<Vec<_>>()
        .join(", ")
}

/// Metres, to 0.1 µm.
fn m3(v: DVec3) -> String {
    fixed(&v.to_array(), 7)
}

fn m3f(v: Vec3) -> String {
    m3(v.as_dvec3())
}

/// Values joined by ", ", each written by `write`.
fn joined<T>(values: &[T], write: impl Fn(&T) -> String) -> String {
    values.iter().map(write).collect::<Vec<_>>().join(", ")
}

/// An f32 exactly (shortest text that reads back to the same f32).
fn exact(values: &[f32]) -> String {
    joined(values, |v| format!("{v}"))
}

fn hex(values: &[u32]) -> String {
    joined(values, |v| format!("0x{v:08X}"))
}

fn render(tables: &[Table]) -> String {
    let mut out = String::new();
    for table in tables {
        out.push_str(&format!("\n{}\n\n", table.caption));
        out.push_str(&format!("| {} |\n", table.header.join(" | ")));
        out.push_str(&format!("|{}\n", "---|".repeat(table.header.len())));
        for (key, cells) in &table.rows {
            out.push_str(&format!("| {key} | {} |\n", cells.join(" | ")));
        }
    }
    out
}

/// Every value of the worked example, computed with the public core API.
fn example_tables() -> Vec<Table> {
    let params = documented_styling();
    let document = example_document(&params);
    let hair = example_hair(&document);
    let textures = &hair.textures;
    let files = bundle_files(&hair).expect("export");
    let manifest: Manifest =
        serde_json::from_slice(&files.last().expect("manifest").1).expect("manifest parses");
    let block = &textures.atlas.blocks[0];
    let mut tables = Vec::new();

    // The manifest.
    let mut t = Table::new(
        "**Manifest** (the parts the example uses)",
        &["key", "value"],
    );
    t.row(
        "`hair_mesh.size`",
        vec![fixed(&manifest.hair_mesh.size.map(f64::from), 0)],
    );
    t.row(
        "`uv.size`",
        vec![fixed(&manifest.uv.size.map(f64::from), 0)],
    );
    t.row(
        "`w.size`, `u.size`, `v.size`",
        vec![fixed(&manifest.w.size.map(f64::from), 0)],
    );
    t.row("`max_layers`", vec![manifest.max_layers.to_string()]);
    t.row("`position_offset`", vec![exact(&manifest.position_offset)]);
    let b = &manifest.bundles[0];
    t.row(
        "`bundles[0].origin`",
        vec![fixed(&b.origin.map(f64::from), 0)],
    );
    t.row(
        "`bundles[0].corner_of_block`",
        vec![fixed(&b.corner_of_block.map(f64::from), 0)],
    );
    t.row("`bundles[0].layers`", vec![b.layers.to_string()]);
    t.row(
        "`bundles[0].styling_group`",
        vec![b.styling_group.to_string()],
    );
    t.row(
        "`strands_per_bundle`",
        vec![manifest.strands_per_bundle.to_string()],
    );
    t.row(
        "entries in `quad_samples`, `triangle_samples`",
        vec![fixed(
            &[
                manifest.quad_samples.len() as f64,
                manifest.triangle_samples.len() as f64,
            ],
            0,
        )],
    );
    t.row("`quad_samples[0]`", vec![exact(&manifest.quad_samples[0])]);
    tables.push(t);

    // The textures at the block's four texels.
    let corners = [[0u32, 0u32], [1, 0], [1, 1], [0, 1]];
    let mut t = Table::new(
        "**Texels** of the block (f32, exact): block corner 0 = texel (0, 0), 1 = (1, 0), 2 = (1, 1), 3 = (0, 1)",
        &[
            "texture, slice",
            "corner 0",
            "corner 1",
            "corner 2",
            "corner 3",
        ],
    );
    let texel_row = |t: &mut Table,
                     name: &str,
                     texture: &hairloom_core::runtime::textures::Texture3d,
                     z: u32,
                     channels: usize| {
        let cells = corners
            .iter()
            .map(|[x, y]| {
                let v = texture
                    .get(block.origin[0] + x, block.origin[1] + y, z)
                    .to_array();
                exact(&v[..channels])
            })
            .collect();
        t.row(&format!("{name} {z}"), cells);
    };
    for z in 0..textures.hair_mesh.depth {
        texel_row(&mut t, "hair_mesh", &textures.hair_mesh, z, 3);
    }
    texel_row(&mut t, "uv", &textures.uv, 0, 2);
    for z in 0..textures.w.depth {
        texel_row(&mut t, "w", &textures.w, z, 1);
    }
    for z in 0..textures.u.depth {
        texel_row(&mut t, "u", &textures.u, z, 3);
    }
    for z in 0..textures.v.depth {
        texel_row(&mut t, "v", &textures.v, z, 3);
    }
    tables.push(t);

    // Where q0, m, q1 come from: column 0's first cubic.
    let column = &document.hair_mesh.columns[0];
    let segments = curve_segments(&column.positions);
    let cubic = segments[0];
    let [first, second] = cubic_to_quadratics(&cubic);
    let mut t = Table::new(
        "**Curve** of column 0 (block corner 0), segment 0, in f64: the cubic and its two quadratics",
        &["quantity", "value (m)"],
    );
    for (i, b) in cubic.iter().enumerate() {
        t.row(&format!("b{i}"), vec![m3(*b)]);
    }
    t.row("q0 = b0 + ¾(b1 − b0)", vec![m3(first[1])]);
    t.row("m = (q0 + q1)/2", vec![m3(first[2])]);
    t.row("q1 = b3 + ¾(b2 − b3)", vec![m3(second[1])]);
    tables.push(t);

    // The root and its random values.
    let sample = hair.samples.quad[0];
    let root = strand_root(
        block,
        sample,
        0,
        sample_rank(0, hair.strands_per_bundle as usize),
    );
    let (s, t_coord) =
        Atlas::sample_block_coords(block, DVec2::new(sample[0] as f64, sample[1] as f64));
    let weights = Atlas::corner_weights(block, s, t_coord);
    let mirror = StrandGen {
        textures,
        filtering: Filtering::Exact,
    };
    let input = mirror.strand_input(&root, &params);
    let root_uv = input.root_uv;
    let mut t = Table::new("**Root** of strand 0", &["quantity", "value"]);
    t.row("block coordinates (s, t)", vec![fixed(&[s, t_coord], 7)]);
    t.row("texel coordinates P", vec![exact(&root.texel)]);
    t.row(
        "weights of face corners 0, 1, 2, 3 (= block corners here)",
        vec![fixed(&weights, 7)],
    );
    t.row("root uv", vec![fixed(&root_uv.to_array(), 7)]);
    let p = root_uv * params.variation_per_uv;
    let cell = p.floor();
    t.row("root uv × variation_per_uv", vec![fixed(&p.to_array(), 6)]);
    t.row("lattice cell (ix, iy)", vec![fixed(&cell.to_array(), 0)]);
    let (ix, iy) = (cell.x as i64 as u32, cell.y as i64 as u32);
    let chain: Vec<u32> = (1..=4)
        .map(|n| hash_values(&[params.seed, 1, ix, iy][..n]))
        .collect();
    t.row("pcg(0), pcg(1)", vec![hex(&[pcg_hash(0), pcg_hash(1)])]);
    t.row("hash chain of (seed, 1, ix, iy)", vec![hex(&chain)]);
    let lattice: Vec<f64> = [(0, 0), (1, 0), (0, 1), (1, 1)]
        .iter()
        .map(|&(dx, dy)| hash_to_unit(hash_values(&[params.seed, 1, ix + dx, iy + dy])))
        .collect();
    t.row(
        "channel 1 lattice L00, L10, L01, L11",
        vec![fixed(&lattice, 8)],
    );
    for channel in 1..=8 {
        t.row(
            &format!("ξ{}", subscript(channel)),
            vec![fixed(&[strand_random(&params, root_uv, channel)], 7)],
        );
    }
    for channel in 9..=12 {
        t.row(
            &format!("cell_random({channel})"),
            vec![fixed(&[strand_cell_random(&params, root_uv, channel)], 7)],
        );
    }
    let stray_value = strand_cell_random(&params, root_uv, 9);
    t.row(
        "stray (cell_random(9) < stray.fraction): 1 yes, 0 no",
        vec![u8::from(stray_value < params.stray.fraction).to_string()],
    );
    t.row(
        "λ_len",
        vec![fixed(&[strand_length_fraction(&params, root_uv)], 7)],
    );
    let xi = |channel| strand_random(&params, root_uv, channel);
    let radius = params.curl.radius_m * (1.0 + params.curl.radius_jitter * (2.0 * xi(2) - 1.0));
    t.row("curl radius at the root (m)", vec![fixed(&[radius], 7)]);
    let x_clump = root_uv * params.clump.clumps_per_uv;
    let strand_styling = StrandStyling::new(&params, root_uv);
    t.row(
        "lock_phase(x_c, 44), lock_phase(x_c, 45)",
        vec![fixed(
            &[
                lock_phase(x_clump, params.seed, 44, 1.0).to_array(),
                lock_phase(x_clump, params.seed, 45, params.wave.lock_phase_spread).to_array(),
            ]
            .concat(),
            7,
        )],
    );
    t.row(
        "curl e (blended phase)",
        vec![fixed(&strand_styling.curl_phase.to_array(), 7)],
    );
    t.row(
        "wave e (blended phase)",
        vec![fixed(&strand_styling.wave_phase.to_array(), 7)],
    );
    let (key_u, key_v, key_frizz) = (16.0 * xi(3), 16.0 * xi(4), 16.0 * xi(7));
    t.row("noise keys k_u, k_v", vec![fixed(&[key_u, key_v], 6)]);
    t.row("frizz key k_f", vec![fixed(&[key_frizz], 6)]);
    t.row(
        "frizz applies (ξ₆ < fraction): 1 yes, 0 no",
        vec![u8::from(xi(6) < params.frizz.fraction).to_string()],
    );
    t.row(
        "clump x_c = root uv × clumps_per_uv",
        vec![fixed(&x_clump.to_array(), 6)],
    );
    let pull = clump_pull(x_clump, params.seed);
    t.row("clump pull Δ", vec![fixed(&pull.to_array(), 7)]);
    let sub_pull = clump_pull_on(root_uv * params.clump.sub_clumps_per_uv, params.seed, 42);
    t.row("sub-clump pull Δ_s", vec![fixed(&sub_pull.to_array(), 7)]);
    let centre = root.centre_texel;
    t.row("centre strand texel", vec![exact(&centre)]);
    tables.push(t);

    // The strand, vertex by vertex.
    let header: Vec<String> = std::iter::once("quantity".to_string())
        .chain(SHOWN.iter().map(|k| format!("k = {k}")))
        .collect();
    let header: Vec<&str> = header.iter().map(String::as_str).collect();
    let mut t = Table::new(
        &format!("**Strand 0**, {VERTICES} vertices (positions in m)"),
        &header,
    );
    let texel = Vec2::from_array(root.texel);
    let n = VERTICES;
    let mut rows: Vec<(String, Vec<String>)> = Vec::new();
    let mut first_slices = Vec::new();
    let mut push = |key: &str, k_index: usize, text: String| {
        if let Some(row) = rows.iter_mut().find(|(k, _)| k == key) {
            row.1.push(text);
        } else {
            assert_eq!(k_index, 0);
            rows.push((key.to_string(), vec![text]));
        }
    };
    for (index, &k) in SHOWN.iter().enumerate() {
        let along = k as f64 / (n - 1) as f64;
        let tau = (root.layers as f64 * input.length_fraction * along) as f32;
        let segment = (tau.floor() as u32).min(root.layers - 1);
        let local = tau - segment as f32;
        let a = 3 * segment;
        let (half, q) = if local < 0.5 {
            (0, local * 2.0)
        } else {
            (1, local * 2.0 - 1.0)
        };
        let (z_a, z_b) = if half == 0 {
            (a as f32 + q, a as f32 + 1.0 + q / 2.0)
        } else {
            (a as f32 + 1.5 + q / 2.0, a as f32 + 2.0 + q)
        };
        let fa = fetch(
            &textures.hair_mesh,
            texel.extend(z_a + 0.5),
            Filtering::Exact,
        )
        .truncate();
        let fb = fetch(
            &textures.hair_mesh,
            texel.extend(z_b + 0.5),
            Filtering::Exact,
        )
        .truncate();
        let position = mirror.strand_position(texel, root.layers, tau);
        let layer = |texture| fetch(texture, texel.extend(tau + 0.5), Filtering::Exact);
        let u = layer(&textures.u).truncate().as_dvec3().normalize();
        let v = layer(&textures.v).truncate().as_dvec3().normalize();
        let w_axis = u.cross(v).normalize();
        let w = layer(&textures.w).x as f64;
        let centre = mirror
            .strand_position(Vec2::from_array(root.centre_texel), root.layers, tau)
            .as_dvec3();
        let twisted = twist(&params, position.as_dvec3(), centre, w_axis, w);
        let styling = StylingInput {
            u,
            v,
            w_axis,
            root_uv,
            w,
            along,
        };
        let op = |keep: Op| styling_offset(&only(&params, keep), &styling);
        let [curl, noise, clump, frizz, wave, stray] = [
            Op::Curl,
            Op::Noise,
            Op::Clump,
            Op::Frizz,
            Op::Wave,
            Op::Stray,
        ]
        .map(op);
        let styled = mirror.styled_vertex(&input, k, n);
        let sum = twisted + curl + noise + clump + frizz + wave + stray;
        assert!(
            sum.as_vec3().distance(styled) < 1e-7,
            "k {k}: the ops add up to the mirror's vertex"
        );
        first_slices.push((segment, half));
        push("along = k / (V − 1)", index, fixed(&[along], 7));
        push("τ = n · λ_len · along", index, fixed(&[tau as f64], 7));
        push(
            "segment, half",
            index,
            fixed(&[segment as f64, half as f64], 0),
        );
        push(
            "a = 3 · segment, q",
            index,
            format!("{a}, {}", fixed(&[q as f64], 7)),
        );
        push("z_A, z_B", index, fixed(&[z_a as f64, z_b as f64], 7));
        push("A = fetch(z_A + ½)", index, m3f(fa));
        push("B = fetch(z_B + ½)", index, m3f(fb));
        push("position = A + (B − A) q", index, m3f(position));
        push("w", index, fixed(&[w], 7));
        push("û", index, fixed(&u.to_array(), 7));
        push("v̂", index, fixed(&v.to_array(), 7));
        push("ŵ = normalize(û × v̂)", index, fixed(&w_axis.to_array(), 7));
        push("centre strand point", index, m3(centre));
        let smooth = |edge: f64, x: f64| {
            if edge <= 0.0 {
                return f64::from(u8::from(x > 0.0));
            }
            let t = (x / edge).clamp(0.0, 1.0);
            t * t * (3.0 - 2.0 * t)
        };
        let tau_f64 = std::f64::consts::TAU;
        let curl_psi = tau_f64
            * params.curl.turns_per_m
            * w
            * (1.0 + (params.curl.rate_tip_scale - 1.0) * along * 0.5);
        push("curl ψ (rad)", index, fixed(&[curl_psi], 6));
        push(
            "ramp(curl.ramp_in_m, w)",
            index,
            fixed(&[smooth(params.curl.ramp_in_m, w)], 7),
        );
        let (mut nu, mut nv, mut gain, mut frequency) =
            (0.0, 0.0, 1.0, params.noise.frequency_per_m);
        for octave in 0..params.noise.octaves.max(1) {
            nu += gain * value_noise_1d(frequency * w + key_u, params.seed, 10 + octave);
            nv += gain * value_noise_1d(frequency * w + key_v, params.seed, 20 + octave);
            gain *= 0.5;
            frequency *= 2.0;
        }
        push("noise sums (n_u, n_v)", index, fixed(&[nu, nv], 7));
        let fw = params.frizz.frequency_per_m * w + key_frizz;
        let frizz_ab = [
            value_noise_1d(fw, params.seed, 30),
            value_noise_1d(fw + 500.0, params.seed, 31),
        ];
        push("frizz (a, b)", index, fixed(&frizz_ab, 7));
        let wave_psi = tau_f64 * params.wave.frequency_per_m * w;
        push("wave ψ (rad)", index, fixed(&[wave_psi], 6));
        push(
            "ramp(wave.ramp_in_m, w)",
            index,
            fixed(&[smooth(params.wave.ramp_in_m, w)], 7),
        );
        push("after twist", index, m3(twisted));
        push("curl offset", index, m3(curl));
        push("noise offset", index, m3(noise));
        push("clump offset", index, m3(clump));
        push("frizz offset", index, m3(frizz));
        push("wave offset", index, m3(wave));
        push("stray offset", index, m3(stray));
        push("styled vertex", index, m3f(styled));
    }
    // The prose under the region walks through these four cases.
    assert_eq!(
        first_slices,
        [(0, 0), (0, 1), (1, 0), (1, 1)],
        "the shown vertices cover every quadratic"
    );
    for (key, cells) in rows {
        t.row(&key, cells);
    }
    let root_position = mirror.styled_vertex(&input, 0, n);
    t.row(
        "root (k = 0, never styled)",
        vec![
            m3f(root_position),
            String::new(),
            String::new(),
            String::new(),
        ],
    );
    tables.push(t);

    // Level of detail.
    let mut t = Table::new("**Level of detail**", &["quantity", "value"]);
    let delta = hash_to_unit(pcg_hash(0));
    t.row("δ₀ = unit(pcg(0))", vec![fixed(&[delta], 8)]);
    let per = hair.strands_per_bundle;
    t.row(
        "L = 0.5: strands ⌈L (N + δ₀)⌉, thickness",
        vec![fixed(
            &[
                strand_count(0.5, per, delta) as f64,
                thickness_factor(0.5, per),
            ],
            0,
        )],
    );
    t.row(
        "L = 1: strands (clamped to N)",
        vec![strand_count(1.0, per, delta).to_string()],
    );
    let lod = vertex_lod(0.3, 5, 0.5);
    t.row(
        "L = 0.3, max 5, λ = 0.5: e, ẽ, γ",
        vec![format!(
            "{}, {}, {}",
            lod.e,
            lod.e_tilde,
            fixed(&[lod.gamma], 7)
        )],
    );
    let mut strand: Vec<DVec3> = (0..n)
        .map(|k| mirror.styled_vertex(&input, k, n).as_dvec3())
        .collect();
    morph_odd_vertices(&mut strand, 0.25);
    t.row("vertex 1 morphed with γ = 0.25", vec![m3(strand[1])]);
    tables.push(t);

    // Root mapping of rotated quads and of triangles (other blocks than this bundle's).
    let mut t = Table::new(
        "**Root mapping checks** (blocks other than the example's): `quad_samples[1]` on a quad block at each rotation, `triangle_samples[0]` on a triangle block",
        &[
            "block",
            "sample",
            "block coordinates (s, t)",
            "weights of face corners 0, 1, 2, 3",
        ],
    );
    let quad = hair.samples.quad[1];
    for r in 0..4u8 {
        let rotated = BundleBlock {
            bundle: 0,
            origin: [0, 0],
            corner_of_block: [0, 1, 2, 3].map(|c| (c + r) % 4),
            layers: 1,
        };
        let (s, t_coord) =
            Atlas::sample_block_coords(&rotated, DVec2::new(quad[0] as f64, quad[1] as f64));
        t.row(
            &format!("quad, `corner_of_block` {:?}", rotated.corner_of_block),
            vec![
                exact(&quad),
                fixed(&[s, t_coord], 7),
                fixed(&Atlas::corner_weights(&rotated, s, t_coord), 7),
            ],
        );
    }
    let triangle_sample = hair.samples.triangle[0];
    let triangle = BundleBlock {
        bundle: 0,
        origin: [0, 0],
        corner_of_block: [0, 1, 2, 2],
        layers: 1,
    };
    let (s, t_coord) = Atlas::sample_block_coords(
        &triangle,
        DVec2::new(triangle_sample[0] as f64, triangle_sample[1] as f64),
    );
    t.row(
        "triangle, `corner_of_block` [0, 1, 2, 2]",
        vec![
            exact(&triangle_sample),
            fixed(&[s, t_coord], 7),
            fixed(&Atlas::corner_weights(&triangle, s, t_coord), 7),
        ],
    );
    tables.push(t);
    tables
}

#[derive(Clone, Copy, PartialEq)]
enum Op {
    Curl,
    Noise,
    Clump,
    Frizz,
    Wave,
    Stray,
}

/// `params` with every offset op but `keep` switched off.
fn only(params: &StylingParams, keep: Op) -> StylingParams {
    let mut p = params.clone();
    if keep != Op::Curl {
        p.curl.radius_m = 0.0;
    }
    if keep != Op::Noise {
        p.noise.amplitude_m = 0.0;
    }
    if keep != Op::Clump {
        p.clump.strength = 0.0;
        p.clump.sub_strength = 0.0;
    }
    // The stray selection stays (it decides clump and frizz); only its drift is kept or not.
    if keep != Op::Stray {
        p.stray.amplitude_m = 0.0;
    }
    if keep != Op::Frizz {
        p.frizz.amplitude_m = 0.0;
    }
    if keep != Op::Wave {
        p.wave.amplitude_m = 0.0;
    }
    p
}

fn subscript(n: u32) -> String {
    n.to_string()
        .chars()
        .map(|c| char::from_u32(0x2080 + c.to_digit(10).unwrap_or(0)).unwrap_or(c))
        .collect()
}

// ---------------------------------------------------------------------------------------
// Check 1: the document prints what the code computes.

/// A number as printed: its value and how far a correctly rounded print may be from it.
#[derive(Debug)]
enum Token {
    Hex(u32),
    Number { value: f64, tolerance: f64 },
}

fn tokens(cells: &[&str]) -> Result<Vec<Token>, String> {
    let mut out = Vec::new();
    for cell in cells {
        for word in cell.split([',', ' ', '(', ')', '[', ']']) {
            if word.is_empty() {
                continue;
            }
            if let Some(digits) = word.strip_prefix("0x") {
                let value = u32::from_str_radix(digits, 16).map_err(|e| format!("{word}: {e}"))?;
                out.push(Token::Hex(value));
                continue;
            }
            let value: f64 = word.parse().map_err(|e| format!("{word:?}: {e}"))?;
            let decimals = word.split_once('.').map_or(0, |(_, d)| d.len());
            let tolerance = 0.5 * 10f64.powi(-(decimals as i32)) * (1.0 + 1e-9) + 1e-15;
            out.push(Token::Number { value, tolerance });
        }
    }
    Ok(out)
}

/// `(key, value cells)` of every table row between the markers (headers and rules skipped).
fn rows(region: &str) -> Vec<(String, Vec<String>)> {
    let lines: Vec<&str> = region.lines().map(str::trim).collect();
    let is_rule = |line: &str| line.starts_with("|-") || line.starts_with("|:");
    let mut out = Vec::new();
    for (i, line) in lines.iter().enumerate() {
        if !line.starts_with('|') || is_rule(line) {
            continue;
        }
        if lines.get(i + 1).is_some_and(|next| is_rule(next)) {
            continue; // a header
        }
        let cells: Vec<String> = line
            .trim_matches('|')
            .split(" | ")
            .map(|c| c.trim().to_string())
            .collect();
        if let Some((key, values)) = cells.split_first() {
            out.push((key.clone(), values.to_vec()));
        }
    }
    out
}

fn documented_region() -> &'static str {
    let start = DOC
        .find(BEGIN)
        .expect("docs/runtime-format.md has the example-values begin marker");
    let start = start + DOC[start..].find('\n').expect("marker line ends");
    let end = DOC
        .find(END)
        .expect("docs/runtime-format.md has the end marker");
    &DOC[start..end]
}

#[test]
fn the_documented_example_is_what_the_code_computes() {
    let generated = render(&example_tables());
    let expected = rows(&generated);
    let documented = rows(documented_region());
    let mut problems = Vec::new();
    let keys =
        |rows: &[(String, Vec<String>)]| rows.iter().map(|r| r.0.clone()).collect::<Vec<_>>();
    if keys(&expected) != keys(&documented) {
        problems.push("the rows differ".to_string());
    } else {
        for ((key, ours), (_, theirs)) in expected.iter().zip(&documented) {
            let ours_text: Vec<&str> = ours.iter().map(String::as_str).collect();
            let theirs_text: Vec<&str> = theirs.iter().map(String::as_str).collect();
            let (ours, theirs) = match (tokens(&ours_text), tokens(&theirs_text)) {
                (Ok(a), Ok(b)) => (a, b),
                (a, b) => {
                    problems.push(format!("{key}: unreadable ({a:?} / {b:?})"));
                    continue;
                }
            };
            let same = ours.len() == theirs.len()
                && ours.iter().zip(&theirs).all(|pair| match pair {
                    (Token::Hex(a), Token::Hex(b)) => a == b,
                    (
                        Token::Number { value: a, .. },
                        Token::Number {
                            value: b,
                            tolerance,
                        },
                    ) => (a - b).abs() <= *tolerance,
                    _ => false,
                });
            if !same {
                problems.push(format!(
                    "{key}: the document says {theirs_text:?}, the code computes {ours_text:?}"
                ));
            }
        }
    }
    assert!(
        problems.is_empty(),
        "docs/runtime-format.md's worked example is out of date:\n{}\n\nThe region should read:\n{}",
        problems.join("\n"),
        generated
    );
}

// ---------------------------------------------------------------------------------------
// Check 2: an implementation of the document's formulas, in f32 like the shader, matches
// the CPU mirror of strand_gen.wgsl.

mod from_the_document {
    use glam::{Vec2, Vec3, Vec4};
    use hairloom_core::model::styling::StylingParams;
    use hairloom_core::runtime::textures::Texture3d;

    const TAU: f32 = std::f32::consts::TAU;

    /// "Filtering": texel centres at i + ½, clamp to the edge, x then y then z.
    pub fn fetch(texture: &Texture3d, coord: Vec3) -> Vec4 {
        let axis = |c: f32, size: u32| {
            let x = (c - 0.5).clamp(0.0, (size - 1) as f32);
            let i0 = (x.floor() as u32).min(size.saturating_sub(2));
            (i0, (i0 + 1).min(size - 1), x - i0 as f32)
        };
        let (x0, x1, fx) = axis(coord.x, texture.width);
        let (y0, y1, fy) = axis(coord.y, texture.height);
        let (z0, z1, fz) = axis(coord.z, texture.depth);
        // mix(a, b, f) = a + (b − a) f, as the shader writes it.
        let mix = |a: Vec4, b: Vec4, f: f32| a + (b - a) * f;
        let plane = |z| {
            let bottom = mix(texture.get(x0, y0, z), texture.get(x1, y0, z), fx);
            let top = mix(texture.get(x0, y1, z), texture.get(x1, y1, z), fx);
            mix(bottom, top, fy)
        };
        mix(plane(z0), plane(z1), fz)
    }

    pub fn pcg(value: u32) -> u32 {
        let state = value.wrapping_mul(747_796_405).wrapping_add(2_891_336_453);
        let word = ((state >> ((state >> 28) + 4)) ^ state).wrapping_mul(277_803_737);
        (word >> 22) ^ word
    }

    pub fn hash(values: &[u32]) -> u32 {
        values.iter().fold(0x6A09_E667, |h, &v| pcg(h ^ v))
    }

    fn unit(hash: u32) -> f32 {
        (hash >> 8) as f32 / 16_777_216.0
    }

    fn fade(t: f32) -> f32 {
        t * t * t * (t * (t * 6.0 - 15.0) + 10.0)
    }

    fn cell(x: f32) -> u32 {
        x as i32 as u32
    }

    fn noise2(p: Vec2, seed: u32, channel: u32) -> f32 {
        let c = p.floor();
        let (ix, iy) = (cell(c.x), cell(c.y));
        let l = |dx: u32, dy: u32| {
            unit(hash(&[
                seed,
                channel,
                ix.wrapping_add(dx),
                iy.wrapping_add(dy),
            ]))
        };
        let (fx, fy) = (fade(p.x - c.x), fade(p.y - c.y));
        let bottom = l(0, 0) + (l(1, 0) - l(0, 0)) * fx;
        let top = l(0, 1) + (l(1, 1) - l(0, 1)) * fx;
        bottom + (top - bottom) * fy
    }

    fn noise1(x: f32, seed: u32, channel: u32) -> f32 {
        let c = x.floor();
        let i = cell(c);
        let l = |d: u32| 2.0 * unit(hash(&[seed, channel, i.wrapping_add(d)])) - 1.0;
        l(0) + (l(1) - l(0)) * fade(x - c)
    }

    fn ramp(edge: f32, x: f32) -> f32 {
        if edge <= 0.0 {
            return if x > 0.0 { 1.0 } else { 0.0 };
        }
        let t = (x / edge).clamp(0.0, 1.0);
        t * t * (3.0 - 2.0 * t)
    }

    /// The 3×3 centres around `x` on lattice channels `k`, `k + 1`: `(cx, cy, d, K)`, dy outer.
    fn centres(x: Vec2, seed: u32, k: u32) -> Vec<(u32, u32, Vec2, f32)> {
        let base = x.floor();
        let mut out = Vec::with_capacity(9);
        for dy in -1..=1 {
            for dx in -1..=1 {
                let c = base + Vec2::new(dx as f32, dy as f32);
                let (ix, iy) = (cell(c.x), cell(c.y));
                let centre = c + Vec2::new(
                    unit(hash(&[seed, k, ix, iy])),
                    unit(hash(&[seed, k + 1, ix, iy])),
                );
                let d = centre - x;
                let weight = (1.0 - d.dot(d)).max(0.0);
                out.push((ix, iy, d, weight * weight));
            }
        }
        out
    }

    fn clump_pull(x: Vec2, seed: u32, k: u32) -> Vec2 {
        let (mut weighted, mut total) = (Vec2::ZERO, 0.0);
        for (_, _, d, weight) in centres(x, seed, k) {
            weighted += weight * d;
            total += weight;
        }
        weighted / (total + 0.25)
    }

    fn lock_phase(x: Vec2, seed: u32, k: u32, spread: f32) -> Vec2 {
        let (mut weighted, mut total) = (Vec2::ZERO, 0.0);
        for (cx, cy, _, weight) in centres(x, seed, 40) {
            let beta = spread * TAU * unit(hash(&[seed, k, cx, cy]));
            weighted += weight * Vec2::new(beta.cos(), beta.sin());
            total += weight;
        }
        weighted / (total + 0.25)
    }

    fn blend(own: Vec2, coherence: f32, lock: impl FnOnce() -> Vec2) -> Vec2 {
        if coherence <= 0.0 {
            return own;
        }
        let c = coherence.min(1.0);
        let e = own * (1.0 - c) + lock() * c;
        e / e.length().max(0.5)
    }

    /// One bundle as the manifest gives it.
    pub struct Bundle {
        pub origin: [u32; 2],
        pub corner_of_block: [u8; 4],
        pub layers: u32,
    }

    /// The five textures and the position offset.
    pub struct Textures<'a> {
        pub hair_mesh: &'a Texture3d,
        pub uv: &'a Texture3d,
        pub w: &'a Texture3d,
        pub u: &'a Texture3d,
        pub v: &'a Texture3d,
        pub position_offset: Vec3,
        /// `root_maps`: `(W, H, RGBA8 bytes)`, or none (every map 1).
        pub root_maps: Option<(u32, u32, &'a [u8])>,
    }

    /// "Painted maps": `root_map_values(uv)`, f32, bilinear between texel centres.
    fn root_map_values(t: &Textures<'_>, uv: Vec2) -> [f32; 3] {
        let Some((w, h, bytes)) = t.root_maps else {
            return [1.0; 3];
        };
        let size = Vec2::new(w as f32, h as f32);
        let mut x = (uv * size - 0.5).clamp(Vec2::ZERO, size - 1.0);
        if x.x.is_nan() {
            x.x = 0.0;
        }
        if x.y.is_nan() {
            x.y = 0.0;
        }
        let i0 = [
            (x.x.floor() as u32).min(w - 1),
            (x.y.floor() as u32).min(h - 1),
        ];
        let i1 = [(i0[0] + 1).min(w - 1), (i0[1] + 1).min(h - 1)];
        let f = x - Vec2::new(i0[0] as f32, i0[1] as f32);
        let texel =
            |tx: u32, ty: u32, c: usize| bytes[(4 * (ty * w + tx)) as usize + c] as f32 / 255.0;
        [0, 1, 2].map(|c| {
            let bottom =
                texel(i0[0], i0[1], c) + (texel(i1[0], i0[1], c) - texel(i0[0], i0[1], c)) * f.x;
            let top =
                texel(i0[0], i1[1], c) + (texel(i1[0], i1[1], c) - texel(i0[0], i1[1], c)) * f.x;
            bottom + (top - bottom) * f.y
        })
    }

    fn position(t: &Textures<'_>, p: Vec2, layers: u32, tau: f32) -> Vec3 {
        let tau = tau.clamp(0.0, layers as f32);
        let segment = (tau.floor() as u32).min(layers - 1);
        let f = tau - segment as f32;
        let a = (3 * segment) as f32;
        let (z_a, z_b, q) = if f < 0.5 {
            let q = 2.0 * f;
            (a + q, a + 1.0 + q / 2.0, q)
        } else {
            let q = 2.0 * f - 1.0;
            (a + 1.5 + q / 2.0, a + 2.0 + q, q)
        };
        let first = fetch(t.hair_mesh, p.extend(z_a + 0.5)).truncate();
        let second = fetch(t.hair_mesh, p.extend(z_b + 0.5)).truncate();
        first + (second - first) * q + t.position_offset
    }

    /// The strand `j` of `per_bundle` at `sample` (a manifest sample) in `bundle`, `n`
    /// vertices.
    pub fn strand(
        t: &Textures<'_>,
        bundle: &Bundle,
        (j, per_bundle, sample): (usize, usize, [f32; 2]),
        params: &StylingParams,
        n: usize,
    ) -> Vec<Vec3> {
        let triangle = bundle.corner_of_block[2] == bundle.corner_of_block[3];
        let (st, centre_st) = if triangle {
            let (a, b) = (sample[0], sample[1]);
            let s = if 1.0 - b > 0.0 {
                (a / (1.0 - b)).clamp(0.0, 1.0)
            } else {
                0.0
            };
            (Vec2::new(s, b), Vec2::new(0.5, 1.0 / 3.0))
        } else {
            let mut st = Vec2::from_array(sample);
            for _ in 0..bundle.corner_of_block[0] % 4 {
                st = Vec2::new(st.y, 1.0 - st.x);
            }
            (st, Vec2::splat(0.5))
        };
        let origin = Vec2::new(bundle.origin[0] as f32, bundle.origin[1] as f32) + 0.5;
        let (p, centre) = (origin + st, origin + centre_st);
        let root_uv = fetch(t.uv, p.extend(0.5)).truncate().truncate();
        let seed = params.seed;
        let cells = root_uv * params.variation_per_uv as f32;
        let xi = |channel| noise2(cells, seed, channel);
        let cell_random = |channel| unit(hash(&[seed, channel, cell(cells.x), cell(cells.y)]));
        let stray = params.stray.fraction > 0.0 && cell_random(9) < params.stray.fraction as f32;
        let fraction = params.length.fraction.clamp(0.0, 1.0) as f32;
        let mut length = if fraction > 0.0 {
            1.0 - fraction * xi(5)
        } else {
            1.0
        };
        if stray {
            let shortest = params.stray.length_min.clamp(0.0, 1.0) as f32;
            length *= shortest + (1.0 - shortest) * cell_random(10);
        }
        let hairline = &params.hairline;
        if hairline.width_m > 0.0 {
            let distance = fetch(t.hair_mesh, p.extend(0.5)).w;
            let rank = (j as f32 + 0.5) / per_bundle as f32;
            let x = (distance.max(0.0) / hairline.width_m as f32).clamp(0.0, 1.0);
            let s_h = x * x * (3.0 - 2.0 * x);
            let grows = rank < 1.0 - (1.0 - hairline.edge_density as f32) * (1.0 - s_h);
            length *= if grows {
                1.0 - (1.0 - hairline.edge_length as f32) * (1.0 - s_h)
            } else {
                0.0
            };
        }
        let [m_d, m_l, m_c] = root_map_values(t, root_uv);
        let rank = (j as f32 + 0.5) / per_bundle as f32;
        length *= if rank < m_d { m_l } else { 0.0 };
        let x_c = root_uv * params.clump.clumps_per_uv.max(1.0) as f32;
        let layers = bundle.layers;
        (0..n)
            .map(|k| {
                let drawn = k as f32 / (n - 1) as f32;
                let tau = layers as f32 * length * drawn;
                // A cut strand's ops read `along · m_l`.
                let along = drawn * m_l;
                let mut x = position(t, p, layers, tau);
                if k == 0 || length <= 0.0 {
                    return x;
                }
                let z = p.extend(tau + 0.5);
                let u = fetch(t.u, z).truncate().normalize();
                let v = fetch(t.v, z).truncate().normalize();
                let axis = u.cross(v).normalize();
                let w = fetch(t.w, z).x;
                let twist = params.twist.turns_per_m as f32;
                if twist != 0.0 && w > 0.0 {
                    let c = position(t, centre, layers, tau);
                    let angle = TAU * twist * w;
                    let o = x - c;
                    x = c
                        + o * angle.cos()
                        + axis.cross(o) * angle.sin()
                        + axis * axis.dot(o) * (1.0 - angle.cos());
                }
                if w <= 0.0 {
                    return x;
                }
                let mut offset = Vec3::ZERO;
                let curl = &params.curl;
                if curl.radius_m != 0.0 {
                    let own = Vec2::new((TAU * xi(1)).cos(), (TAU * xi(1)).sin());
                    let e = blend(own, curl.clump_coherence as f32, || {
                        lock_phase(x_c, seed, 44, 1.0)
                    });
                    let psi = TAU
                        * curl.turns_per_m as f32
                        * w
                        * (1.0 + (curl.rate_tip_scale as f32 - 1.0) * along / 2.0);
                    let (a, b) = (
                        e.x * psi.cos() - e.y * psi.sin(),
                        e.x * psi.sin() + e.y * psi.cos(),
                    );
                    let r = curl.radius_m as f32
                        * (1.0 + curl.radius_jitter as f32 * (2.0 * xi(2) - 1.0))
                        * (1.0 + (curl.radius_tip_scale as f32 - 1.0) * along);
                    offset += ramp(curl.ramp_in_m as f32, w) * r * (a * u + b * v);
                }
                let noise = &params.noise;
                if noise.amplitude_m != 0.0 {
                    let (key_u, key_v) = (16.0 * xi(3), 16.0 * xi(4));
                    let (mut nu, mut nv, mut gain) = (0.0, 0.0, 1.0);
                    let mut frequency = noise.frequency_per_m as f32;
                    for octave in 0..noise.octaves.clamp(1, 8) {
                        nu += gain * noise1(frequency * w + key_u, seed, 10 + octave);
                        nv += gain * noise1(frequency * w + key_v, seed, 20 + octave);
                        gain *= 0.5;
                        frequency *= 2.0;
                    }
                    offset += noise.amplitude_m as f32 * along * (nu * u + nv * v);
                }
                let clump = &params.clump;
                if (clump.strength != 0.0 || clump.sub_strength != 0.0) && !stray {
                    let main = if clump.strength != 0.0 {
                        clump_pull(x_c, seed, 40)
                    } else {
                        Vec2::ZERO
                    };
                    let sub = if clump.sub_strength != 0.0 {
                        clump_pull(root_uv * clump.sub_clumps_per_uv as f32, seed, 42)
                    } else {
                        Vec2::ZERO
                    };
                    let pull = (main * (clump.strength * clump.radius_m) as f32
                        + sub * (clump.sub_strength * clump.sub_radius_m) as f32)
                        * m_c;
                    offset +=
                        along.powf(clump.tightening.max(0.0) as f32) * (pull.x * u + pull.y * v);
                }
                let frizz = &params.frizz;
                if frizz.amplitude_m != 0.0 && (stray || xi(6) < frizz.fraction as f32) {
                    let key = 16.0 * xi(7);
                    let f = frizz.frequency_per_m as f32 * w + key;
                    let a = noise1(f, seed, 30);
                    let b = noise1(f + 500.0, seed, 31);
                    offset += frizz.amplitude_m as f32 * along * along * (a * u + b * v);
                }
                let wave = &params.wave;
                if wave.amplitude_m != 0.0 {
                    let phi = wave.phase_spread as f32 * TAU * xi(8);
                    let e = blend(
                        Vec2::new(phi.cos(), phi.sin()),
                        wave.clump_coherence as f32,
                        || lock_phase(x_c, seed, 45, wave.lock_phase_spread as f32),
                    );
                    let psi = TAU * wave.frequency_per_m as f32 * w;
                    let s = e.x * psi.sin() + e.y * psi.cos();
                    let alpha = wave.direction_rad as f32;
                    let d = alpha.cos() * u + alpha.sin() * v;
                    offset += ramp(wave.ramp_in_m as f32, w) * wave.amplitude_m as f32 * s * d;
                }
                let drift = &params.stray;
                if drift.amplitude_m != 0.0 && stray {
                    let alpha = TAU * cell_random(11);
                    let key = 16.0 * cell_random(12);
                    let f = drift.frequency_per_m as f32 * w + key;
                    let (a, b) = (noise1(f, seed, 50), noise1(f + 500.0, seed, 51));
                    offset += drift.amplitude_m as f32
                        * along
                        * along
                        * ((alpha.cos() + a / 2.0) * u + (alpha.sin() + b / 2.0) * v);
                }
                x + offset
            })
            .collect()
    }
}

#[test]
fn an_implementation_of_the_document_matches_the_cpu_mirror() {
    let params = documented_styling();
    let document = example_document(&params);
    let hair = example_hair(&document);
    let textures = &hair.textures;
    let files = bundle_files(&hair).expect("export");
    let manifest: Manifest =
        serde_json::from_slice(&files.last().expect("manifest").1).expect("manifest parses");
    let ours = from_the_document::Textures {
        hair_mesh: &textures.hair_mesh,
        uv: &textures.uv,
        w: &textures.w,
        u: &textures.u,
        v: &textures.v,
        position_offset: Vec3::from_array(manifest.position_offset),
        root_maps: None,
    };
    let mirror = StrandGen {
        textures,
        filtering: Filtering::Exact,
    };
    let size = document.hair_mesh.size() as f32;
    let entry = &manifest.bundles[0];
    let bundle = from_the_document::Bundle {
        origin: entry.origin,
        corner_of_block: entry.corner_of_block,
        layers: entry.layers,
    };
    let per_bundle = hair.strands_per_bundle as usize;
    let compare = |textures: &_, ours: &from_the_document::Textures<'_>, params: &_| {
        let mirror = StrandGen {
            textures,
            filtering: Filtering::Exact,
        };
        let mut worst = 0.0f32;
        for (j, root) in hair.strand_roots().iter().enumerate() {
            for n in [2, VERTICES, 33] {
                let expected = mirror.styled_strand(root, n, params);
                let sample = (j, per_bundle, manifest.quad_samples[j]);
                let got = from_the_document::strand(ours, &bundle, sample, params, n);
                for (a, b) in got.iter().zip(&expected) {
                    worst = worst.max(a.distance(*b));
                }
            }
        }
        worst
    };
    let worst = compare(textures, &ours, &params);
    eprintln!("from the document vs the CPU mirror: {worst:.3e} m (size {size:.3} m)");
    assert!(worst <= 1e-5 * size, "{worst} m");
    // The hairline op, from the root slice's fourth channel. The example's one bundle is all
    // border (every corner at distance 0), so the test writes distances of its own there.
    let mut hairline_textures = textures.clone();
    let texture = &mut hairline_textures.hair_mesh;
    for (corner, distance) in [(0, 0.0), (1, 0.003), (2, 0.02), (3, 0.007)] {
        let [x, y] = [[0, 0], [1, 0], [1, 1], [0, 1]][corner];
        let origin = hair.textures.atlas.blocks[0].origin;
        let i = texture.index(origin[0] + x, origin[1] + y, 0);
        texture.texels[i].w = distance;
    }
    let mut hairline_params = params.clone();
    hairline_params.hairline = hairloom_core::model::styling::Hairline {
        width_m: 0.012,
        edge_density: 0.4,
        edge_length: 0.5,
    };
    let hairline_mirror = StrandGen {
        textures: &hairline_textures,
        filtering: Filtering::Exact,
    };
    let lengths: Vec<f64> = hair
        .strand_roots()
        .iter()
        .map(|root| {
            hairline_mirror
                .strand_input(root, &hairline_params)
                .length_fraction
        })
        .collect();
    let plain: Vec<f64> = hair
        .strand_roots()
        .iter()
        .map(|root| hairline_mirror.strand_input(root, &params).length_fraction)
        .collect();
    assert!(
        lengths.contains(&0.0) && lengths.iter().zip(&plain).any(|(&l, &p)| l > 0.0 && l < p),
        "the example's strands include thinned and shortened ones: {lengths:?}"
    );
    let ours = from_the_document::Textures {
        hair_mesh: &hairline_textures.hair_mesh,
        ..ours
    };
    let worst = compare(&hairline_textures, &ours, &hairline_params);
    eprintln!("with the hairline: {worst:.3e} m");
    assert!(worst <= 1e-5 * size, "{worst} m");
    // Painted maps, read as the document says: a density ramp across the bundle's uv, half
    // length on one side, clump fading out; loaded back from the bundle's own texture.
    let mut painted = document.clone();
    let (lo, hi) = painted
        .hair_mesh
        .bundles
        .iter()
        .flat_map(|b| b.uvs.iter().copied())
        .fold(
            (glam::DVec2::splat(1.0), glam::DVec2::ZERO),
            |(lo, hi), uv| (lo.min(uv), hi.max(uv)),
        );
    let side = 16u32;
    let image = |value: &dyn Fn(f64) -> f64| -> Vec<f64> {
        (0..side * side)
            .map(|i| {
                let u = ((i % side) as f64 + 0.5) / side as f64;
                value(((u - lo.x) / (hi.x - lo.x).max(1e-9)).clamp(0.0, 1.0))
            })
            .collect()
    };
    for (channel, values) in [
        (RootMapChannel::Density, image(&|s| 0.2 + 0.8 * s)),
        (
            RootMapChannel::Length,
            image(&|s| if s < 0.5 { 0.5 } else { 1.0 }),
        ),
        (RootMapChannel::Clump, image(&|s| 1.0 - s)),
    ] {
        painted
            .root_maps
            .set_channel_from_image(channel, side, side, &values)
            .expect("map");
    }
    let painted_hair = example_hair(&painted);
    let painted_files: std::collections::HashMap<String, Vec<u8>> = bundle_files(&painted_hair)
        .expect("export")
        .into_iter()
        .collect();
    let loaded = load_runtime_asset_from(&painted_files, "memory")
        .expect("loads")
        .hair;
    let maps = &loaded.textures.root_maps;
    let bytes = maps.rgba8();
    let ours_painted = from_the_document::Textures {
        hair_mesh: &loaded.textures.hair_mesh,
        uv: &loaded.textures.uv,
        w: &loaded.textures.w,
        u: &loaded.textures.u,
        v: &loaded.textures.v,
        position_offset: loaded.textures.position_offset,
        root_maps: Some((maps.width(), maps.height(), &bytes)),
    };
    let painted_mirror = StrandGen {
        textures: &painted_hair.textures,
        filtering: Filtering::Exact,
    };
    let grown: Vec<f64> = hair
        .strand_roots()
        .iter()
        .map(|root| painted_mirror.strand_input(root, &params).length_fraction)
        .collect();
    assert!(
        grown.contains(&0.0) && grown.iter().any(|&l| l > 0.0),
        "the maps leave some strands out and grow others: {grown:?}"
    );
    let worst = compare(&painted_hair.textures, &ours_painted, &params);
    eprintln!("with painted maps: {worst:.3e} m");
    assert!(worst <= 1e-5 * size, "{worst} m");
    // The strands compared include strays and clumped strands both.
    let strays: Vec<bool> = hair
        .strand_roots()
        .iter()
        .map(|root| mirror.strand_input(root, &params).styling.stray)
        .collect();
    assert!(
        strays.contains(&true) && strays.contains(&false),
        "{strays:?}"
    );
    // The document's hash check values.
    assert_eq!(from_the_document::pcg(0), pcg_hash(0));
    assert_eq!(
        from_the_document::hash(&[7, 1, 80, 142]),
        hash_values(&[7, 1, 80, 142])
    );
}
