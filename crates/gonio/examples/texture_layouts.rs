//! The inverse HDS map as a texture parameterisation, side by side with latitude–longitude, cube
//! map and equal-area octahedral UVs on generated meshes (docs/TEXTURE.md).
//!
//! `cargo run --release -p gonio --example texture_layouts [FACES] [--sweep] [--hds] [--worst]`
//! (FACES default 100000; `--sweep`: also the ratio bound against the diagram's grid on the
//! ellipsoid, and the time at 10⁶ faces; `--hds`: the HDS layout only; `--worst`: the directions
//! of the three triangles with the lowest and the highest ratio of each HDS mesh; `--big`: only the
//! time at 10⁶ faces, five runs, wall and process CPU seconds — on a shared machine the CPU time
//! is the one to read).

use gonio::mesh::generate::{frequency_for_faces, named_shapes, shape_mesh, Shape};
use gonio::mesh::metrics::{measure, surface_target, Metrics};
use gonio::mesh::param::{area3, signed_area};
use gonio::mesh::{parameterise, Layout, UvMesh, UvOptions};
use std::time::Instant;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let faces: usize = args.iter().find_map(|a| a.parse().ok()).unwrap_or(100_000);
    let sweep = args.iter().any(|a| a == "--sweep");
    let hds_only = args.iter().any(|a| a == "--hds");
    let worst = args.iter().any(|a| a == "--worst");
    if args.iter().any(|a| a == "--big") {
        big_timing(5);
        return;
    }
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
            if hds_only && layout != Layout::Hds {
                continue;
            }
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
                let Metrics {
                    triangles,
                    flipped,
                    degenerate,
                    ratio_range: (lo, hi),
                    ratio_p01_p99: (p01, p99),
                    outside_10_percent: outside,
                    histogram,
                    l2,
                    linf,
                    seam_length,
                    area,
                    ..
                } = measure(&r.mesh, &surface_target, aspect);
                // Share of the surface with ratio in [0.9, 1.1]: bins 0.9–0.95, 0.95–1.05, 1.05–1.1.
                let within = 100.0 * (histogram[3] + histogram[4] + histogram[5]);
                let seam = seam_length / area.sqrt();
                let layout = layout.name();
                println!(
                    "| {name} | {layout} | {aspect} | {triangles} | {flipped} | {degenerate} | {lo:.3} | {hi:.3} | {p01:.3} | {p99:.3} | {within:.1} % | {outside} | {l2:.3} | {linf:.2} | {seam:.2} | {secs:.3} |",
                );
            }
            if worst && layout == Layout::Hds {
                print_worst(name, &r.mesh, r.star.center);
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
    big_timing(2);
}

/// Process CPU seconds (user + system) from /proc/self/stat; NaN where there is none.
fn cpu_seconds() -> f64 {
    let Ok(s) = std::fs::read_to_string("/proc/self/stat") else {
        return f64::NAN;
    };
    // The fields after the command name in parentheses; utime and stime are fields 14 and 15.
    let Some(rest) = s.rsplit(')').next() else {
        return f64::NAN;
    };
    let f: Vec<&str> = rest.split_whitespace().collect();
    let tick = |i: usize| {
        f.get(i)
            .and_then(|x| x.parse::<f64>().ok())
            .unwrap_or(f64::NAN)
    };
    // rest starts at field 3 (state): field k is f[k - 3]; clock ticks of 1/100 s.
    (tick(11) + tick(12)) / 100.0
}

/// The whole `parameterise` call on the asteroid at 10⁶ faces, `runs` times.
fn big_timing(runs: usize) {
    let big = shape_mesh(&named_shapes()[3].1, frequency_for_faces(1_000_000));
    for _ in 0..runs {
        let (t, c) = (Instant::now(), cpu_seconds());
        let r = parameterise(&big, &UvOptions::default()).unwrap();
        println!(
            "asteroid, {} triangles in, {} out: {:.3} s wall, {:.2} s CPU (wall: star check {:.3}, density {:.3}, map {:.3}, UVs and cut {:.3}), {} triangles cut",
            big.triangles.len(),
            r.mesh.triangles.len(),
            t.elapsed().as_secs_f64(),
            cpu_seconds() - c,
            r.seconds[0],
            r.seconds[1],
            r.seconds[2],
            r.seconds[3],
            r.cut_triangles
        );
    }
}

/// The three lowest and highest ratio triangles: ratio, chart, direction of the centroid (θ, φ in
/// degrees) and UV centroid.
fn print_worst(name: &str, mesh: &UvMesh, c: [f64; 3]) {
    let mut rows: Vec<(f64, usize)> = Vec::with_capacity(mesh.triangles.len());
    let (mut su, mut sa) = (0.0, 0.0);
    let mut v = Vec::with_capacity(mesh.triangles.len());
    for t in &mesh.triangles {
        let p = t.map(|k| mesh.positions[k.position as usize]);
        let uv = t.map(|k| mesh.uvs[k.uv as usize]);
        let (a, u) = (area3(p[0], p[1], p[2]), signed_area(uv).abs());
        su += u;
        sa += a;
        v.push((u, a));
    }
    for (i, (u, a)) in v.iter().enumerate() {
        rows.push(((u / su) / (a / sa), i));
    }
    rows.sort_by(|a, b| a.0.total_cmp(&b.0));
    let n = rows.len();
    for &(r, i) in rows[..3].iter().chain(&rows[n - 3..]) {
        let t = mesh.triangles[i];
        let mut g = [0.0; 3];
        let mut q = [0.0; 2];
        for k in t {
            let p = mesh.positions[k.position as usize];
            let uv = mesh.uvs[k.uv as usize];
            for j in 0..3 {
                g[j] += p[j] - c[j];
            }
            q[0] += uv[0] / 3.0;
            q[1] += uv[1] / 3.0;
        }
        let l = (g[0] * g[0] + g[1] * g[1] + g[2] * g[2]).sqrt();
        let th = (g[2] / l).clamp(-1.0, 1.0).acos().to_degrees();
        let ph = g[1].atan2(g[0]).to_degrees();
        println!(
            "  {name}: ratio {r:.3}, chart {}, θ {th:.2}°, φ {ph:.2}°, uv ({:.4}, {:.4})",
            mesh.chart[i], q[0], q[1]
        );
    }
}
