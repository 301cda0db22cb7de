//! The inputs of the instruction-counting drivers (`soa_profile.rs`, `trait_soa_profile.rs`):
//! Halton points and the directions a sampler maps them to, as columns in f64 and f32, made in
//! the setup that every operation's count subtracts.

use gonio::sequence::Halton;
use gonio::Sampler;

/// `count` points of the square and their directions, as rows and as columns of both precisions.
pub struct Inputs {
    /// The points (Halton, skip 1).
    pub pts: Vec<[f64; 2]>,
    /// The directions `s.sample` gives them (the scalar reference).
    pub dirs: Vec<[f64; 3]>,
    /// The points' u and v columns.
    pub uv: [Vec<f64>; 2],
    /// The same in f32.
    pub uv32: [Vec<f32>; 2],
    /// The directions' x, y and z columns.
    pub d: Vec<Vec<f64>>,
    /// The same in f32.
    pub d32: Vec<Vec<f32>>,
}

/// The [`Inputs`] of `count` points through `s`.
pub fn inputs(s: &dyn Sampler, count: usize) -> Inputs {
    let mut pts = vec![[0.0; 2]; count];
    Halton::with_skip(1).fill(0, &mut pts);
    let dirs: Vec<[f64; 3]> = pts.iter().map(|&p| s.sample(p).direction).collect();
    let uv = [0, 1].map(|c| pts.iter().map(|p| p[c]).collect::<Vec<f64>>());
    let d: Vec<Vec<f64>> = (0..3)
        .map(|c| dirs.iter().map(|x| x[c]).collect())
        .collect();
    let f32s = |c: &Vec<f64>| c.iter().map(|&x| x as f32).collect::<Vec<f32>>();
    Inputs {
        uv32: [f32s(&uv[0]), f32s(&uv[1])],
        d32: d.iter().map(f32s).collect(),
        pts,
        dirs,
        uv,
        d,
    }
}
