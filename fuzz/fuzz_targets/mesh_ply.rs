#![no_main]
//! PLY reader (ASCII and both binary encodings): any input gives a mesh or a typed error; a mesh
//! that reads validates and writes back as binary PLY with the same positions and triangles.
use libfuzzer_sys::fuzz_target;

#[path = "../common/mesh_case.rs"]
mod mesh_case;

fuzz_target!(|data: &[u8]| {
    match gonio::mesh::ply::read_ply(data) {
        Ok(r) => {
            let back = gonio::mesh::ply::read_ply(&gonio::mesh::ply::write_ply_binary(&r.mesh))
                .expect("written PLY reads back");
            assert_eq!(back.mesh.triangles, r.mesh.triangles);
            mesh_case::check_mesh(&r.mesh);
        }
        Err(e) => mesh_case::check_error(&e),
    }
});
