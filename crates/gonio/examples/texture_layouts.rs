//! The inverse HDS map as a texture parameterisation, side by side with latitude–longitude, cube
//! map and equal-area octahedral UVs on generated meshes (docs/TEXTURE.md).
//!
//! `cargo run --release -p gonio --example texture_layouts [FACES] [--sweep]`
//! (FACES default 100000; `--sweep`: also the ratio bound against the diagram's grid on the
//! ellipsoid, and the time at 10⁶ faces).

use gonio::mesh::generate::{frequency_for_faces, named_shapes, shape_mesh, Shape};
use gonio::mesh::metrics::{measure, surface_target};
use gonio::mesh::{parameterise, Layout, UvOptions};
use std::time::Instant;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let faces: usize = args.iter().find_map(|a| a.parse().ok()).unwrap_or(100_000);
    let sweep = args.iter().any(|a| a == "--sweep");
    let n = frequency_for_faces(faces);
    println!("| shape | layout | aspect | triangles out | flipped | degenerate | ratio min | ratio max | p1 | p99 | area in [0.9, 1.1] | triangles outside | L2 | L∞ | seam / √area | seconds |");
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|");
    for (name, shape) in named_shapes() {
        let mesh = shape_mesh(&shape, n);
        for layout in [
            Layout::Hds,
            Layout::LatLong,
            Layout::Cube,
            Layout::Octahedral,
        ] {
            let t = Instant::now();
            let r = parameterise(
                &mesh,
                &UvOptions {
                    layout,
                    ..UvOptions::default()
                },
            )
            .expect("star-shaped");
            let secs = t.elapsed().as_secs_f64();
            let aspects: Vec<f64> = if layout == Layout::Hds {
                vec![1.0, 2.0]
            } else {
                vec![layout.native_aspect()]
            };
            for aspect in aspects {
                let m = measure(&r.mesh, &surface_target, aspect);
                // Share of the surface with ratio in [0.9, 1.1]: bins 0.9–0.95, 0.95–1.05, 1.05–1.1.
                let within = m.histogram[3] + m.histogram[4] + m.histogram[5];
                println!(
                    "| {name} | {} | {aspect} | {} | {} | {} | {:.3} | {:.3} | {:.3} | {:.3} | {:.1} % | {} | {:.3} | {:.2} | {:.2} | {secs:.3} |",
                    layout.name(),
                    m.triangles,
                    m.flipped,
                    m.degenerate,
                    m.ratio_range.0,
                    m.ratio_range.1,
                    m.ratio_p01_p99.0,
                    m.ratio_p01_p99.1,
                    100.0 * within,
                    m.outside_10_percent,
                    m.l2,
                    m.linf,
                    m.seam_length / m.area.sqrt(),
                );
            }
        }
    }
    if !sweep {
        return;
    }
    println!();
    println!(
        "| ellipsoid, {} triangles: grid | ratio min | ratio max | p1 | p99 |",
        20 * n * n
    );
    println!("|---|---|---|---|---|");
    let mesh = shape_mesh(&Shape::Ellipsoid([1.0, 0.7, 0.45]), n);
    for g in [9usize, 17, 33, 51, 65, 91] {
        let r = parameterise(
            &mesh,
            &UvOptions {
                grid: Some((g, 2 * (g - 1))),
                ..UvOptions::default()
            },
        )
        .unwrap();
        let m = measure(&r.mesh, &surface_target, 1.0);
        println!(
            "| {g} × {} | {:.3} | {:.3} | {:.3} | {:.3} |",
            2 * (g - 1),
            m.ratio_range.0,
            m.ratio_range.1,
            m.ratio_p01_p99.0,
            m.ratio_p01_p99.1
        );
    }
    println!();
    let big = shape_mesh(&named_shapes()[3].1, frequency_for_faces(1_000_000));
    for _ in 0..2 {
        let t = Instant::now();
        let r = parameterise(&big, &UvOptions::default()).unwrap();
        println!(
            "asteroid, {} triangles: {:.3} s (star check {:.3}, density {:.3}, map {:.3}, UVs and cut {:.3}), {} triangles cut",
            big.triangles.len(),
            t.elapsed().as_secs_f64(),
            r.seconds[0],
            r.seconds[1],
            r.seconds[2],
            r.seconds[3],
            r.cut_triangles
        );
    }
}
