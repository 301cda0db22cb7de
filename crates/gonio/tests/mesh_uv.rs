//! The inverse map as a texture parameterisation on generated meshes (small ones: 20 n² triangles
//! with n ≤ 12, well under a second in total).

use gonio::mesh::generate::{banana, named_shapes, shape_mesh, Shape};
use gonio::mesh::metrics::{measure, surface_target};
use gonio::mesh::param::{area3, signed_area};
use gonio::mesh::{obj, parameterise, Density, Layout, MeshError, UvOptions};

fn opts(layout: Layout) -> UvOptions {
    UvOptions {
        layout,
        ..UvOptions::default()
    }
}

#[test]
fn every_shape_every_layout_has_no_flipped_or_degenerate_triangle() {
    for (name, shape) in named_shapes() {
        let mesh = shape_mesh(&shape, 10);
        for layout in [
            Layout::Hds,
            Layout::LatLong,
            Layout::Cube,
            Layout::Octahedral,
        ] {
            let r = parameterise(&mesh, &opts(layout)).unwrap();
            let m = measure(&r.mesh, &surface_target, 1.0);
            assert_eq!(m.flipped, 0, "{name} {layout:?}");
            assert_eq!(m.degenerate, 0, "{name} {layout:?}");
            assert!(r
                .mesh
                .uvs
                .iter()
                .all(|u| (0.0..=1.0).contains(&u[0]) && (0.0..=1.0).contains(&u[1])));
            // The pieces cover the surface: same total area as the input.
            let a_in: f64 = mesh
                .triangles
                .iter()
                .map(|t| {
                    let p = t.map(|i| mesh.positions[i as usize]);
                    area3(p[0], p[1], p[2])
                })
                .sum();
            assert!((m.area - a_in).abs() < 1e-9 * a_in, "{name} {layout:?}");
            if layout == Layout::Hds {
                // Outward meshes get counter-clockwise UV triangles, all of them.
                for t in &r.mesh.triangles {
                    let uv = t.map(|c| r.mesh.uvs[c.uv as usize]);
                    assert!(signed_area(uv) > 0.0, "{name}");
                }
                // Every triangle lies in one chart of the split layout.
                let seam = r.texture.as_ref().unwrap().seam();
                for (t, &chart) in r.mesh.triangles.iter().zip(&r.mesh.chart) {
                    for c in t {
                        let u = r.mesh.uvs[c.uv as usize][0];
                        if chart == 0 {
                            assert!(u <= seam + 1e-12, "{name}");
                        } else {
                            assert!(u >= seam - 1e-12, "{name}");
                        }
                    }
                }
                // The texture coordinate maps back to the vertex's direction.
                let tex = r.texture.as_ref().unwrap();
                for t in &r.mesh.triangles {
                    for c in t {
                        let p = r.mesh.positions[c.position as usize];
                        let d = [
                            p[0] - r.star.center[0],
                            p[1] - r.star.center[1],
                            p[2] - r.star.center[2],
                        ];
                        let l = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
                        let back = tex.direction(r.mesh.uvs[c.uv as usize]);
                        let err = ((back[0] - d[0] / l).powi(2)
                            + (back[1] - d[1] / l).powi(2)
                            + (back[2] - d[2] / l).powi(2))
                        .sqrt();
                        assert!(err < 1e-6, "{name}: {err}");
                    }
                }
            }
        }
    }
}

#[test]
fn surface_density_is_close_to_uniform_on_an_ellipsoid() {
    let mesh = shape_mesh(&Shape::Ellipsoid([1.0, 0.7, 0.45]), 12);
    let r = parameterise(&mesh, &UvOptions::default()).unwrap();
    let m = measure(&r.mesh, &surface_target, 1.0);
    // 2880 triangles, a 9 × 16 grid: the 1st–99th percentile within 20 % (measured 0.86–1.19).
    assert!(m.ratio_p01_p99.0 > 0.8 && m.ratio_p01_p99.1 < 1.2, "{m:?}");
    // Uniform per steradian is far from uniform over this surface.
    let s = parameterise(
        &mesh,
        &UvOptions {
            density: Density::SolidAngle,
            ..UvOptions::default()
        },
    )
    .unwrap();
    let ms = measure(&s.mesh, &surface_target, 1.0);
    assert!(ms.ratio_range.1 / ms.ratio_range.0 > 3.0 * m.ratio_range.1 / m.ratio_range.0);
}

#[test]
fn vertex_weights_spend_texels_where_asked() {
    let mesh = shape_mesh(&Shape::Ellipsoid([1.0, 1.0, 1.0]), 10);
    // Weight 4 on the upper half, 1 below: the upper hemisphere gets ~4/5 of the square.
    let w: Vec<f64> = mesh
        .positions
        .iter()
        .map(|p| if p[2] > 0.0 { 4.0 } else { 1.0 })
        .collect();
    let r = parameterise(
        &mesh,
        &UvOptions {
            density: Density::VertexWeight(w),
            ..UvOptions::default()
        },
    )
    .unwrap();
    let p_lower = r.texture.unwrap().seam();
    // Measured 0.254: the 9-parallel grid smears the step at the equator (uniform: 0.5).
    assert!((p_lower - 0.2).abs() < 0.07, "{p_lower}");
    let bad = parameterise(
        &mesh,
        &UvOptions {
            density: Density::VertexWeight(vec![0.0; mesh.positions.len()]),
            ..UvOptions::default()
        },
    );
    assert!(matches!(bad, Err(MeshError::Density(_))));
}

#[test]
fn non_star_shaped_and_open_meshes_are_refused() {
    let m = banana(8);
    match parameterise(&m, &UvOptions::default()) {
        Err(MeshError::NotStarShaped {
            failing,
            triangles,
            first_failing,
            ..
        }) => {
            assert!(failing > 0 && failing < triangles);
            assert!(!first_failing.is_empty());
        }
        other => panic!("{other:?}"),
    }
    let mut open = shape_mesh(&Shape::Head, 6);
    open.triangles.truncate(open.triangles.len() - 3);
    match parameterise(&open, &UvOptions::default()) {
        Err(MeshError::NotClosed { boundary_edges, .. }) => assert!(boundary_edges >= 3),
        other => panic!("{other:?}"),
    }
    // A centre outside the shape.
    let s = shape_mesh(&Shape::Ellipsoid([1.0, 1.0, 1.0]), 6);
    let e = parameterise(
        &s,
        &UvOptions {
            center: Some([3.0, 0.0, 0.0]),
            ..UvOptions::default()
        },
    );
    assert!(matches!(e, Err(MeshError::NotStarShaped { .. })), "{e:?}");
}

#[test]
fn an_off_centre_mesh_finds_its_centre() {
    // Shift the asteroid; the centroid still sees every face.
    let mut m = shape_mesh(&named_shapes()[3].1, 8);
    for p in &mut m.positions {
        p[0] += 5.0;
        p[2] -= 2.0;
    }
    let r = parameterise(&m, &UvOptions::default()).unwrap();
    assert!((r.star.center[0] - 5.0).abs() < 0.5);
    assert_eq!(measure(&r.mesh, &surface_target, 1.0).flipped, 0);
}

#[test]
fn obj_written_reads_back() {
    let mesh = shape_mesh(&Shape::Head, 5);
    let r = parameterise(&mesh, &UvOptions::default()).unwrap();
    let text = obj::write_obj(&r.mesh, Some(("head.mtl", "head.png")));
    let back = obj::read_obj(text.as_bytes()).unwrap();
    assert_eq!(back.mesh.triangles.len(), r.mesh.triangles.len());
    assert_eq!(back.mesh.texcoords.len(), r.mesh.uvs.len());
    assert_eq!(back.mesh.positions.len(), r.mesh.positions.len());
    assert!(obj::write_mtl("head.png").contains("map_Kd head.png"));
}

#[test]
fn mutated_files_give_a_mesh_or_an_error() {
    use rand::{Rng, SeedableRng};
    let mesh = shape_mesh(&Shape::Ellipsoid([1.0, 0.8, 0.6]), 2);
    let r = parameterise(&mesh, &UvOptions::default()).unwrap();
    let obj_text = obj::write_obj(&r.mesh, None).into_bytes();
    let ply_bin = gonio::mesh::ply::write_ply_binary(&mesh);
    let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(29);
    let (mut ok, mut err) = (0, 0);
    for round in 0..600 {
        let mut b = if round % 2 == 0 {
            obj_text.clone()
        } else {
            ply_bin.clone()
        };
        for _ in 0..rng.gen_range(1..4) {
            let i = rng.gen_range(0..b.len());
            match rng.gen_range(0..3) {
                0 => b[i] = rng.gen(),
                1 => b.truncate(i),
                _ => b[i] = b"0123456789-. \n/e"[rng.gen_range(0..16)],
            }
            if b.is_empty() {
                break;
            }
        }
        let read = if round % 2 == 0 {
            obj::read_obj(&b).map(|r| r.mesh)
        } else {
            gonio::mesh::ply::read_ply(&b).map(|r| r.mesh)
        };
        match read {
            Ok(m) => {
                ok += 1;
                m.validate().unwrap();
                let _ = parameterise(&m, &UvOptions::default());
            }
            Err(_) => err += 1,
        }
    }
    // Both outcomes occur: the mutations are neither all harmless nor all fatal.
    assert!(ok > 0 && err > 0, "{ok} {err}");
}
