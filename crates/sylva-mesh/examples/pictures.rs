//! Writes every leaf atlas, petal cut-out and bark picture Sylva draws as PNG files, to look
//! at them: `cargo run --release -p sylva-mesh --example pictures -- OUT_DIR`.

use sylva_core::species::{BarkKind, LeafKind};
use sylva_mesh::picture::Picture;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let out = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "target/pictures".into());
    std::fs::create_dir_all(&out)?;
    let mut all: Vec<Picture> = LeafKind::ALL.into_iter().map(Picture::Leaves).collect();
    all.extend([
        Picture::Petal(None),
        Picture::Petal(Some(6)),
        Picture::Petal(Some(7)),
    ]);
    for k in BarkKind::ALL {
        all.extend([Picture::Bark(k), Picture::BarkNormal(k)]);
    }
    for p in all {
        let png = p.png()?;
        let path = format!("{out}/{}.png", p.name());
        std::fs::write(&path, png.as_slice())?;
        println!("{path}: {} bytes", png.len());
    }
    Ok(())
}
