//! What the mesh fuzz targets (`mesh_obj`, `mesh_ply`) check (issue 40): an accepted mesh holds
//! only finite attributes, a refusal's message is printable (no control bytes echoed from the
//! file), and the parameterisation of a small mesh gives finite positions, UVs and centre or an
//! error whose message holds no NaN.

use gonio::mesh::{Mesh, MeshError};

/// A reader's error: printable.
pub fn check_error(e: &MeshError) {
    let m = e.to_string();
    assert!(!m.chars().any(|c| c.is_control()), "{m:?}");
}

/// An accepted mesh: valid, finite, and (when small) parameterised to finite numbers.
pub fn check_mesh(mesh: &Mesh) {
    mesh.validate()
        .expect("a mesh the reader accepts validates");
    assert!(mesh.positions.iter().flatten().all(|c| c.is_finite()));
    assert!(mesh.normals.iter().flatten().all(|c| c.is_finite()));
    assert!(mesh.texcoords.iter().flatten().all(|c| c.is_finite()));
    assert!(mesh
        .vertex_properties
        .iter()
        .all(|p| p.values.iter().all(|c| c.is_finite())));
    if mesh.triangles.len() <= 256 {
        match gonio::mesh::parameterise(mesh, &gonio::mesh::UvOptions::default()) {
            Ok(r) => {
                assert!(r.mesh.positions.iter().flatten().all(|c| c.is_finite()));
                assert!(r.mesh.uvs.iter().flatten().all(|c| c.is_finite()));
                assert!(r.mesh.normals.iter().flatten().all(|c| c.is_finite()));
                assert!(r.star.center.iter().all(|c| c.is_finite()));
                assert!(r.star.solid_angle_sum.is_finite());
            }
            Err(e) => {
                let m = e.to_string();
                assert!(!m.contains("NaN"), "{m}");
                check_error(&e);
            }
        }
    }
}
