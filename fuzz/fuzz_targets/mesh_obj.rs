#![no_main]
//! OBJ reader: any input gives a mesh or a typed error; a mesh that reads validates, and a small
//! one goes through the star check and (when star-shaped) the parameterisation without panicking.
use libfuzzer_sys::fuzz_target;

#[path = "../common/mesh_case.rs"]
mod mesh_case;

fuzz_target!(|data: &[u8]| {
    match gonio::mesh::obj::read_obj(data) {
        Ok(r) => mesh_case::check_mesh(&r.mesh),
        Err(e) => mesh_case::check_error(&e),
    }
});
