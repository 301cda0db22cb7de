#![no_main]
//! OBJ reader: any input gives a mesh or a typed error; a mesh that reads validates, and a small
//! one goes through the star check and (when star-shaped) the parameterisation without panicking.
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(r) = gonio::mesh::obj::read_obj(data) {
        r.mesh.validate().expect("a mesh the reader accepts validates");
        if r.mesh.triangles.len() <= 256 {
            let _ = gonio::mesh::parameterise(&r.mesh, &gonio::mesh::UvOptions::default());
        }
    }
});
