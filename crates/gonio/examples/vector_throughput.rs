//! Throughput of the vector instructions that bound the explicit kernels, on this CPU: AVX-512
//! division, square root, gather and FMA, f64 and f32, each over eight independent chains (so the
//! figure is throughput, not latency). `docs/PERFORMANCE.md` uses its output to size the kernels'
//! floors.
//!
//! ```sh
//! cargo run --release -p gonio --example vector_throughput [GHz]
//! ```
//! `GHz` (default 2.45, this VM's measured clock) converts nanoseconds to cycles.

#[cfg(target_arch = "x86_64")]
mod x86 {
    use std::arch::x86_64::*;
    use std::hint::black_box;
    use std::time::Instant;

    /// What one timed loop runs.
    #[derive(Clone, Copy)]
    pub enum Op {
        DivPd,
        SqrtPd,
        DivPs,
        SqrtPs,
        GatherPd,
        FmaPd,
    }

    /// Seconds per instruction of `op`, best of 5 runs of `iters` × 8 instructions.
    pub fn time(op: Op, iters: u64) -> f64 {
        (0..5)
            // SAFETY: `main` calls this only where the CPU has AVX-512 F.
            .map(|_| unsafe { run(op, iters) })
            .fold(f64::INFINITY, f64::min)
    }

    #[target_feature(enable = "avx512f")]
    fn run(op: Op, iters: u64) -> f64 {
        let mut a = [_mm512_set1_pd(1.000_000_1); 8];
        let b = _mm512_set1_pd(0.999_999_9);
        let mut af = [_mm512_set1_ps(1.0001); 8];
        let bf = _mm512_set1_ps(0.9999);
        let table: Vec<f64> = (0..64).map(|i| 1.0 + i as f64 * 1e-9).collect();
        let base = _mm256_setr_epi32(0, 3, 5, 7, 11, 13, 17, 19);
        let t0 = Instant::now();
        for it in 0..iters {
            for k in 0..8 {
                match op {
                    Op::DivPd => a[k] = _mm512_div_pd(b, a[k]),
                    Op::SqrtPd => a[k] = _mm512_sqrt_pd(a[k]),
                    Op::DivPs => af[k] = _mm512_div_ps(bf, af[k]),
                    Op::SqrtPs => af[k] = _mm512_sqrt_ps(af[k]),
                    Op::GatherPd => {
                        let off = _mm256_set1_epi32((k as u64 + it) as i32);
                        let idx =
                            _mm256_and_si256(_mm256_add_epi32(base, off), _mm256_set1_epi32(63));
                        // SAFETY: every index is in 0..64, the table's length.
                        let g = unsafe { _mm512_i32gather_pd::<8>(idx, table.as_ptr()) };
                        a[k] = _mm512_add_pd(a[k], g);
                    }
                    Op::FmaPd => a[k] = _mm512_fmadd_pd(a[k], b, b),
                }
            }
        }
        let elapsed = t0.elapsed().as_secs_f64();
        black_box((a, af));
        elapsed / (iters as f64 * 8.0)
    }
}

#[cfg(target_arch = "x86_64")]
fn main() {
    use x86::Op;
    if !std::arch::is_x86_feature_detected!("avx512f") {
        println!("this CPU has no AVX-512 F: nothing to measure");
        return;
    }
    let ghz: f64 = std::env::args()
        .nth(1)
        .and_then(|s| s.parse().ok())
        .unwrap_or(2.45);
    println!("instruction | ns | cycles at {ghz} GHz | cycles per lane");
    for (op, name, lanes) in [
        (Op::DivPd, "vdivpd zmm (8 × f64)", 8.0),
        (Op::SqrtPd, "vsqrtpd zmm (8 × f64)", 8.0),
        (Op::DivPs, "vdivps zmm (16 × f32)", 16.0),
        (Op::SqrtPs, "vsqrtps zmm (16 × f32)", 16.0),
        (Op::GatherPd, "vgatherdpd zmm (8 × f64, L1)", 8.0),
        (Op::FmaPd, "vfmadd231pd zmm (8 × f64)", 8.0),
    ] {
        let ns = x86::time(op, 2_000_000) * 1e9;
        let cycles = ns * ghz;
        println!("{name} | {ns:.2} | {cycles:.1} | {:.2}", cycles / lanes);
    }
}

#[cfg(not(target_arch = "x86_64"))]
fn main() {
    println!("this example measures x86-64 AVX-512 instructions: nothing to measure here");
}
