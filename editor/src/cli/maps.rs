//! `hairloom maps PROJECT --density D.png --length L.png --clump C.png --colour C.png
//! [--clear MAP]`: brings maps painted in another tool (over the scalp's uv layout, the glTF's
//! `TEXCOORD_0`) into a project as one undo step. The grey maps' images are read as grey
//! (luminance, 0 black … 1 white); the colour map's as sRGB colour with its alpha as the
//! colour's weight (an image without alpha colours all the hair). Row 0 is `v = 0`, the
//! image's top row, as glTF has it. Images larger than [`MAX_ROOT_MAP_SIDE`] on a side are
//! refused before they are decoded.

use std::path::{Path, PathBuf};

use anyhow::Context as _;
use clap::Args;
use hairloom_core::io::project;
use hairloom_core::model::history::Command;
use hairloom_core::model::root_maps::{MAX_ROOT_MAP_SIDE, RootMapChannel};

#[derive(Args)]
pub struct MapsArgs {
    /// The project to change (written in place unless --out names another file).
    project: PathBuf,
    /// Grey image: the share of strands that grow (white: all, black: none).
    #[arg(long)]
    density: Option<PathBuf>,
    /// Grey image: the share of its length the hair keeps.
    #[arg(long)]
    length: Option<PathBuf>,
    /// Grey image: the share of the Clump op's pull the hair feels.
    #[arg(long)]
    clump: Option<PathBuf>,
    /// Colour image (sRGB): the colour a mass of the hair shows, its alpha the colour's
    /// weight over the material's (transparent: the material's own).
    #[arg(long, alias = "color")]
    colour: Option<PathBuf>,
    /// Forget a painted map (density, length, clump or colour); may repeat.
    #[arg(long, value_parser = parse_channel)]
    clear: Vec<RootMapChannel>,
    /// Write the project here instead.
    #[arg(long)]
    out: Option<PathBuf>,
}

fn parse_channel(text: &str) -> Result<RootMapChannel, String> {
    RootMapChannel::parse(text)
        .ok_or_else(|| format!("{text:?} is not a map: density, length, clump or colour"))
}

/// A grey image as values in `[0, 1]`, refused by name when it is not an image or too large.
pub fn grey_image(path: &Path) -> anyhow::Result<(u32, u32, Vec<f64>)> {
    let grey = open_image(path)?.to_luma32f();
    Ok((
        grey.width(),
        grey.height(),
        grey.pixels().map(|p| p.0[0] as f64).collect(),
    ))
}

/// A colour image as sRGB values and alpha in `[0, 1]`, refused as [`grey_image`] is.
pub fn colour_image(path: &Path) -> anyhow::Result<(u32, u32, Vec<[f64; 4]>)> {
    let rgba = open_image(path)?.to_rgba32f();
    Ok((
        rgba.width(),
        rgba.height(),
        rgba.pixels().map(|p| p.0.map(f64::from)).collect(),
    ))
}

/// An image, refused by name when it is not an image or larger than a painted map may be.
fn open_image(path: &Path) -> anyhow::Result<image::DynamicImage> {
    let reader = image::ImageReader::open(path)
        .with_context(|| format!("{}: cannot open", path.display()))?
        .with_guessed_format()
        .with_context(|| format!("{}: cannot read", path.display()))?;
    let mut limits = image::Limits::default();
    limits.max_image_width = Some(MAX_ROOT_MAP_SIDE);
    limits.max_image_height = Some(MAX_ROOT_MAP_SIDE);
    let mut reader = reader;
    reader.limits(limits);
    reader.decode().map_err(|e| match e {
        image::ImageError::Limits(_) => anyhow::anyhow!(
            "{}: larger than {MAX_ROOT_MAP_SIDE} texels on a side (a painted map's limit)",
            path.display()
        ),
        other => anyhow::anyhow!(
            "{}: not an image this build reads ({other})",
            path.display()
        ),
    })
}

pub fn run(args: MapsArgs) -> anyhow::Result<()> {
    let images = [
        (RootMapChannel::Density, &args.density),
        (RootMapChannel::Length, &args.length),
        (RootMapChannel::Clump, &args.clump),
    ];
    if images.iter().all(|(_, p)| p.is_none()) && args.colour.is_none() && args.clear.is_empty() {
        anyhow::bail!(
            "nothing to do: give --density, --length, --clump or --colour images, or --clear MAP"
        );
    }
    let mut loaded = project::load(&args.project)?;
    let before = loaded.document.clone();
    let mut done = Vec::new();
    for channel in &args.clear {
        loaded.document.root_maps.clear_channel(*channel);
        done.push(format!("cleared {}", channel.label().to_lowercase()));
    }
    for (channel, path) in images {
        let Some(path) = path else { continue };
        let (width, height, values) = grey_image(path)?;
        loaded
            .document
            .root_maps
            .set_channel_from_image(channel, width, height, &values)
            .with_context(|| format!("{}", path.display()))?;
        let mean = values.iter().sum::<f64>() / values.len().max(1) as f64;
        done.push(format!(
            "{} from {} ({width} × {height}, mean {mean:.2})",
            channel.label().to_lowercase(),
            path.display()
        ));
    }
    if let Some(path) = &args.colour {
        let (width, height, values) = colour_image(path)?;
        loaded
            .document
            .root_maps
            .set_colour_from_image(width, height, &values)
            .with_context(|| format!("{}", path.display()))?;
        let coverage = values.iter().map(|v| v[3]).sum::<f64>() / values.len().max(1) as f64;
        done.push(format!(
            "colour from {} ({width} × {height}, mean weight {coverage:.2})",
            path.display()
        ));
    }
    if let Some(command) = Command::record("Import maps", &before, &loaded.document) {
        loaded.history.push(command);
    }
    let out = args.out.as_deref().unwrap_or(&args.project);
    project::save(out, &loaded)?;
    let maps = &loaded.document.root_maps;
    println!(
        "{} → {} (maps {} × {})",
        done.join("; "),
        out.display(),
        maps.width(),
        maps.height()
    );
    Ok(())
}
