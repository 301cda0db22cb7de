//! Writes the generated test shapes of docs/TEXTURE.md as binary PLY files.
//!
//! `cargo run --release -p gonio --example mesh_shapes -- DIR [FACES]` (FACES default 100000):
//! DIR/sphere.ply, ellipsoid.ply, superquadric.ply, asteroid.ply, head.ply, and banana.ply (not
//! star-shaped, for the error path).

use gonio::mesh::generate::{banana, frequency_for_faces, named_shapes, shape_mesh};
use gonio::mesh::ply::write_ply_binary;

fn main() -> std::io::Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let dir = std::path::PathBuf::from(args.first().map(String::as_str).unwrap_or("."));
    let faces: usize = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(100_000);
    let n = frequency_for_faces(faces);
    std::fs::create_dir_all(&dir)?;
    for (name, shape) in named_shapes() {
        std::fs::write(
            dir.join(format!("{name}.ply")),
            write_ply_binary(&shape_mesh(&shape, n)),
        )?;
    }
    std::fs::write(dir.join("banana.ply"), write_ply_binary(&banana(n)))?;
    Ok(())
}
