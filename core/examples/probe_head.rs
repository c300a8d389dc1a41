use hairloom_core::import::*;
fn main() {
    let m = import_file(std::path::Path::new("../shared/data/head/LeePerrySmith.glb"), &ImportOptions { max_quad_fold_deg: std::env::args().nth(1).map(|a| a.parse().unwrap()).unwrap_or(60.0), ..Default::default() }).unwrap();
    println!("{} verts, {} faces, {} quads, {} tris, uv {}, src tris {}", m.positions.len(), m.faces.len(), m.quad_count(), m.triangle_count(), m.has_uv, m.source_triangles);
    let (mut lo, mut hi) = (glam::DVec3::splat(1e9), glam::DVec3::splat(-1e9));
    for p in &m.positions { lo = lo.min(*p); hi = hi.max(*p); }
    println!("bbox {lo} {hi}");
    // profile: for y slices, x extent and z extent
    for k in 0..20 { let y0 = lo.y + (hi.y-lo.y)*k as f64/20.0; let y1 = y0 + (hi.y-lo.y)/20.0;
      let s: Vec<_> = m.positions.iter().filter(|p| p.y>=y0 && p.y<y1).collect();
      let xr = s.iter().fold((1e9f64,-1e9f64),|a,p|(a.0.min(p.x),a.1.max(p.x)));
      let zr = s.iter().fold((1e9f64,-1e9f64),|a,p|(a.0.min(p.z),a.1.max(p.z)));
      println!("y {:.2}: n {} x {:.2}..{:.2} z {:.2}..{:.2}", y0, s.len(), xr.0, xr.1, zr.0, zr.1);
    }
}
