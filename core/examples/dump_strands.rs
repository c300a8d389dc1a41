//! Writes the reference strands of a project as text, one strand per line
//! (`x y z x y z …`), for plotting: `dump_strands PROJECT STRANDS_PER_BUNDLE > out.txt`.
use hairloom_core::strands::reference::{StrandOptions, generate};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let path = args
        .next()
        .ok_or("usage: dump_strands PROJECT [STRANDS_PER_BUNDLE]")?;
    let per_bundle: u32 = args.next().map(|a| a.parse()).transpose()?.unwrap_or(16);
    let project = hairloom_core::io::project::load(std::path::Path::new(&path))?;
    let options = StrandOptions {
        strands_per_bundle: per_bundle,
        vertices_log2: 5,
        ..StrandOptions::default()
    };
    for strand in generate(&project.document, &options) {
        let line: Vec<String> = strand
            .points
            .iter()
            .map(|p| format!("{:.6} {:.6} {:.6}", p.x, p.y, p.z))
            .collect();
        println!("{}", line.join(" "));
    }
    Ok(())
}
