//! A driver for instruction counting (callgrind) of the structure-of-arrays batches as the
//! bindings call them: through `&dyn Sampler` (`Batches::sample_batch_soa`, `pdf_batch_soa`,
//! `invert_batch_soa` and the `_f32` twins, the float32 map), on the HDS hemisphere map and the
//! split sphere map of a "lobes" diagram. Runs ONE operation over 2¹⁶ Halton points, so that
//! (instructions of a run − instructions of the `setup` run of the same map) / 2¹⁶ is the cost per
//! point (issue 36's ±3 % check; docs/API.md, "One map house"):
//!
//! ```sh
//! cargo build --release -p gonio --example trait_soa_profile
//! for map in hemisphere sphere; do for op in setup sample-f64 pdf-f64 invert-f64 \
//!     sample-f32 pdf-f32 invert-f32; do
//!   valgrind --tool=callgrind --callgrind-out-file=/dev/null \
//!     target/release/examples/trait_soa_profile $map $op 2>&1 | grep 'refs'
//! done; done
//! ```

mod common;

use gonio::synthetic::{random_hemisphere, Family};
use gonio::{Batches, Diagram, HemisphereMap, Sampler, SphereMap};
use std::hint::black_box;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let map = args.get(1).map_or("hemisphere", |s| s.as_str());
    let op = args.get(2).map_or("setup", |s| s.as_str());
    let count = 1usize << 16;
    let hemi = random_hemisphere(Family::Lobes, 46, 73, false, 7);
    let s: Box<dyn Sampler> = match map {
        "sphere" => {
            // The hemisphere's lobes above, and the same mirrored and scaled below (a split
            // sphere with both maps).
            let n = hemi.theta().len();
            let mut theta = hemi.theta().to_vec();
            theta.extend(
                hemi.theta()[..n - 1]
                    .iter()
                    .rev()
                    .map(|t| std::f64::consts::PI - t),
            );
            let m = hemi.phi().len();
            let mut values = vec![0.0; m * (2 * n - 1)];
            for i in 0..m {
                for j in 0..n {
                    let x = hemi.value(i, j);
                    values[i * (2 * n - 1) + j] = x;
                    values[i * (2 * n - 1) + 2 * n - 2 - j] = 0.5 * x + 0.1;
                }
            }
            let d = Diagram::new(theta, hemi.phi().to_vec(), values).unwrap();
            Box::new(SphereMap::new(&d).unwrap())
        }
        _ => Box::new(HemisphereMap::new(&hemi).unwrap()),
    };
    let common::profile::Inputs {
        uv: [u, v],
        uv32: [u32s, v32s],
        d,
        d32,
        ..
    } = common::profile::inputs(s.as_ref(), count);
    let mut o = vec![vec![0.0f64; count]; 4];
    let mut o32 = vec![vec![0.0f32; count]; 4];
    // The float32 map is built on the first f32 call: make it in the setup of every op.
    {
        let [a, b, c, p] = &mut o32[..] else {
            unreachable!("four columns")
        };
        s.sample_batch_soa_f32(
            &u32s[..1],
            &v32s[..1],
            [&mut a[..1], &mut b[..1], &mut c[..1]],
            &mut p[..1],
        );
    }
    let [x, y, z, p] = &mut o[..] else {
        unreachable!("four columns")
    };
    let [x32, y32, z32, p32] = &mut o32[..] else {
        unreachable!("four columns")
    };
    match op {
        "setup" => {}
        "sample-f64" => s.sample_batch_soa(black_box(&u), &v, [x, y, z], p),
        "pdf-f64" => s.pdf_batch_soa([black_box(&d[0]), &d[1], &d[2]], p),
        "invert-f64" => s.invert_batch_soa([black_box(&d[0]), &d[1], &d[2]], [x, y]),
        "sample-f32" => s.sample_batch_soa_f32(black_box(&u32s), &v32s, [x32, y32, z32], p32),
        "pdf-f32" => s.pdf_batch_soa_f32([black_box(&d32[0]), &d32[1], &d32[2]], p32),
        "invert-f32" => s.invert_batch_soa_f32([black_box(&d32[0]), &d32[1], &d32[2]], [x32, y32]),
        other => {
            eprintln!("unknown operation {other}");
            std::process::exit(2);
        }
    }
    black_box((&o, &o32));
}
