//! The sizes every batch path of the project shares, and the one rule by which a float32 batch
//! call is evaluated by a float64 one.
//!
//! * [`CHUNK`]: points per stack buffer. Every batch path that converts, partitions or checks its
//!   input (the [`crate::Sampler`] batch defaults, the HDS sphere's split by hemisphere, the f32
//!   widening, the C ABI's and the Python package's validation) works on at most this many
//!   points at a time in buffers on the stack, so nothing is allocated per call.
//! * [`PAR_CHUNK`]: points per rayon task in every parallel batch function (the library's
//!   `*_par` functions, the Python package's batches, [`crate::Sequence::fill_par`]). Each output
//!   depends only on its own input, so results do not depend on the number of threads.
//!
//! This module depends on no other module of the crate: the sampler contract, the HDS maps'
//! vector layer and the bindings all read their sizes from here.

/// Points per stack buffer of a batch call: 256.
///
/// Why 256: a multiple of every vector width of the kernels (4 and 8 f64 lanes), and small enough
/// that the largest set of buffers of one call (the split sphere's partition: two sides of three
/// f64 columns and their positions, about 20 KiB) stays on the stack and in the L1/L2 cache,
/// while the per-chunk overhead (one backend dispatch, one loop) is spread over enough points to
/// be invisible (`docs/PERFORMANCE.md`).
pub const CHUNK: usize = 256;

/// Points per rayon task in the parallel batch functions: 4096 (16 stack chunks).
///
/// Why 4096: a task then runs for tens of microseconds (the HDS forward map costs 10–40 ns a
/// point), long enough that rayon's scheduling (about a microsecond a task) costs under a few
/// per cent, and short enough that a batch of 10⁵ points still splits into two dozen tasks that
/// balance across the threads.
pub const PAR_CHUNK: usize = 4096;

/// Scales each widened float32 direction `(x[k], y[k], z[k])` of the first `n` entries to unit
/// length in f64.
///
/// An f32 unit vector is unit only to within f32 rounding (~1e-7); the f64 maps expect unit
/// vectors to within f64 rounding (a horizon direction rounded to f32 can lie "beyond the map's
/// edge" by 1e-7 otherwise). One division per direction (the f32 results do not see the last bits
/// of the scale); a direction of zero or non-finite length passes unchanged.
pub(crate) fn renormalise(d: [&mut [f64]; 3], n: usize) {
    let [x, y, z] = d;
    for k in 0..n {
        let l = (x[k] * x[k] + y[k] * y[k] + z[k] * z[k]).sqrt();
        let s = if l > 0.0 && l.is_finite() {
            1.0 / l
        } else {
            1.0
        };
        x[k] *= s;
        y[k] *= s;
        z[k] *= s;
    }
}

/// Panics, naming the call, unless every length in `lens` equals `n` (unequal slices are a
/// programming error of the caller, not an input error).
pub(crate) fn check_len(what: &str, n: usize, lens: &[usize]) {
    assert!(
        lens.iter().all(|&l| l == n),
        "{what}: slices differ in length"
    );
}
