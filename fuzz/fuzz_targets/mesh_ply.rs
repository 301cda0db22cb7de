#![no_main]
//! PLY reader (ASCII and both binary encodings): any input gives a mesh or a typed error; a mesh
//! that reads validates and writes back as binary PLY with the same positions and triangles.
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(r) = gonio::mesh::ply::read_ply(data) {
        r.mesh.validate().expect("a mesh the reader accepts validates");
        let back = gonio::mesh::ply::read_ply(&gonio::mesh::ply::write_ply_binary(&r.mesh))
            .expect("written PLY reads back");
        assert_eq!(back.mesh.triangles, r.mesh.triangles);
        if r.mesh.triangles.len() <= 256 {
            let _ = gonio::mesh::parameterise(&r.mesh, &gonio::mesh::UvOptions::default());
        }
    }
});
