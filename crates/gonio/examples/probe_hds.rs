//! Profiling probe (temporary): HDS forward and inverse in a loop.
use gonio::sequence::Halton;
use gonio::synthetic::{random_hemisphere, Family};
use gonio::{HemisphereMap, Sample, Sampler};
use std::hint::black_box;
fn main() {
    let args: Vec<String> = std::env::args().collect();
    let n: usize = args.get(1).map_or(181, |s| s.parse().unwrap());
    let m: usize = args.get(2).map_or(361, |s| s.parse().unwrap());
    let what = args.get(3).map_or("fwd", |s| s.as_str()).to_string();
    let d = random_hemisphere(Family::Lobes, n, m, false, 7);
    let s = HemisphereMap::new(&d).unwrap();
    let mut pts = vec![[0.0; 2]; 1 << 16];
    Halton::with_skip(1).fill(0, &mut pts);
    let mut out = vec![Sample::default(); pts.len()];
    s.sample_batch(&pts, &mut out);
    let t = std::time::Instant::now();
    for _ in 0..60 {
        if what == "fwd" {
            s.sample_batch(black_box(&pts), &mut out);
        } else {
            let mut a = 0.0;
            for o in &out {
                a += s.invert(black_box(o.direction)).unwrap()[0];
            }
            black_box(a);
        }
    }
    println!(
        "{what}: {:.1} ns",
        t.elapsed().as_secs_f64() * 1e9 / (60.0 * pts.len() as f64)
    );
}
