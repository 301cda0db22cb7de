//! `gonio bench FILE [--json]`: build time, table memory and per-sample cost of every sampling
//! method on one diagram, measured on this machine.
//!
//! Every method maps the **same** points (the Halton sequence in bases 2 and 3 from index 1,
//! generated once, outside the timed loops) and, for `pdf` and `invert`, the directions it produced
//! itself. One-thread costs are the median over several repeats of the thread's **CPU time** per
//! sample (`clock_gettime(CLOCK_THREAD_CPUTIME_ID)` on Linux, wall time elsewhere), so time spent
//! descheduled on a busy machine does not count; batch costs are wall time (that is what threads
//! buy) over at least 2¹⁸ points (the same points repeated), so their scaling factor is only
//! meaningful on an otherwise idle machine.

use anyhow::{Context, Result};
use gonio::baselines::Rejection;
use gonio::batch::Soa;
use gonio::clock::{process_cpu_ns, thread_cpu_ns};
use gonio::mapping::batch::{invert_soa_par, pdf_soa_par, sample_soa_par, SoaSampler};
use gonio::mapping::simd::{Backend, BatchFloat};
use gonio::mapping::Float32Map;
use gonio::sampler::sample_batch_par;
use gonio::sequence::Halton;
use gonio::{Batches, Built};
use gonio::{Diagram, Domain, HemisphereMap, Method, Point2, Sample, Sampler, SphereMap, Vec3};
use serde::Serialize;
use std::fmt;
use std::hint::black_box;
use std::time::Instant;

/// Repeats of every one-thread measurement; the median is reported.
const REPEATS: usize = 7;
/// Repeats of the batch measurements.
const BATCH_REPEATS: usize = 5;
/// Fewest points of a batch measurement (64 chunks of 4096).
const MIN_BATCH: usize = 1 << 18;

/// The machine the numbers were taken on.
#[derive(Debug, Clone, Serialize)]
pub struct Machine {
    /// CPU model from `/proc/cpuinfo`, if readable.
    pub cpu_model: Option<String>,
    /// Logical cores available to this process.
    pub logical_cores: usize,
    /// Threads used for the batch measurement.
    pub batch_threads: usize,
    /// `"thread-cpu"` or `"wall"`: the clock of the one-thread measurements.
    pub single_thread_clock: String,
    /// The 1-minute load average at the start (`/proc/loadavg`), if readable: above the core count
    /// the batch scaling is not meaningful.
    pub load_average: Option<f64>,
}

/// The measurements of one method.
#[derive(Debug, Clone, Serialize)]
pub struct MethodBench {
    /// The method's name (`hds`, `piecewise-constant`, …).
    pub method: String,
    /// Why the method could not be built (then every number below is absent).
    pub error: Option<String>,
    /// Construction time, milliseconds (wall).
    pub build_ms: Option<f64>,
    /// [`Sampler::memory_bytes`] of the built sampler.
    pub memory_bytes: Option<usize>,
    /// `sample`, one thread, ns per sample (median).
    pub forward_ns: Option<f64>,
    /// `invert` of the method's own samples, one thread, ns per direction (median); absent for
    /// methods without an inverse.
    pub inverse_ns: Option<f64>,
    /// `pdf` of the method's own samples, one thread, ns per direction (median).
    pub pdf_ns: Option<f64>,
    /// `sample_batch_par` in a one-thread pool, wall ns per sample (median).
    pub batch_one_thread_ns: Option<f64>,
    /// `sample_batch_par` on all batch threads, wall ns per sample (median).
    pub batch_all_threads_ns: Option<f64>,
    /// `batch_one_thread_ns / batch_all_threads_ns`: the measured speed-up of the batch.
    pub batch_scaling: Option<f64>,
    /// Process CPU time per sample of the one-thread batch over that of the all-thread batch (1.0
    /// = the threads add no work). On a machine busy with other jobs the wall-clock scaling
    /// understates what the threads would give; this ratio times the thread count is the speed-up
    /// an idle machine with that many free cores would allow, at most.
    pub batch_cpu_ratio: Option<f64>,
    /// Rejection sampling only: the probability that one proposal is accepted.
    pub acceptance: Option<f64>,
}

/// The result of [`run_bench`]: serialisable (for `--json`) and displayable (an aligned table).
#[derive(Debug, Clone, Serialize)]
pub struct BenchReport {
    /// What was measured (normally the file name).
    pub label: String,
    /// Parallels N of the diagram.
    pub n_parallels: usize,
    /// Meridians M of the diagram.
    pub n_meridians: usize,
    /// `"hemisphere"` or `"sphere"`: the domain the samplers were built for.
    pub domain: String,
    /// Points per measurement.
    pub samples: usize,
    /// The paper's table size for this grid, M·N + 2M + 2 floats (for comparison with the memory).
    pub paper_table_floats: usize,
    /// The machine.
    pub machine: Machine,
    /// One entry per requested method, in the order given.
    pub methods: Vec<MethodBench>,
    /// The HDS map's SIMD batch paths (`--soa`), absent otherwise.
    pub soa: Option<SoaBench>,
}

/// Wall nanoseconds per point of the HDS map's structure-of-arrays batch paths
/// (`gonio::mapping::batch`), best of 5 after a warm-up, over the uniform Halton points (forward)
/// and the f64 directions they map to (pdf, inverse; rounded to f32 for the f32 paths).
#[derive(Debug, Clone, Serialize)]
pub struct SoaTimes {
    /// `sample_soa_par` in f64 (directions and pdf).
    pub forward_f64_ns: f64,
    /// `pdf_soa_par` in f64.
    pub pdf_f64_ns: f64,
    /// `invert_soa_par` in f64.
    pub inverse_f64_ns: f64,
    /// `sample_soa_par` in f32.
    pub forward_f32_ns: f64,
    /// `pdf_soa_par` in f32.
    pub pdf_f32_ns: f64,
    /// `invert_soa_par` in f32.
    pub inverse_f32_ns: f64,
    /// The float32 map's (`gonio::mapping::Float32Map`) `sample_soa_par`: f32 tables and
    /// arithmetic.
    pub forward_float32_ns: f64,
    /// The float32 map's `pdf_soa_par`.
    pub pdf_float32_ns: f64,
    /// The float32 map's `invert_soa_par`.
    pub inverse_float32_ns: f64,
}

/// The SoA measurements: in a one-thread pool and on all batch threads.
#[derive(Debug, Clone, Serialize)]
pub struct SoaBench {
    /// The SIMD backend the CPU runs (`avx512`, `avx2+fma` or `portable`).
    pub backend: String,
    /// Threads of the `all` measurement.
    pub threads: usize,
    /// One thread.
    pub one: SoaTimes,
    /// All batch threads.
    pub all: SoaTimes,
}

/// `gonio bench FILE [--json]`: loads the input, runs [`run_bench`] and prints the report (an aligned
/// table, or one pretty-printed JSON object with `--json`).
pub fn run(args: &crate::args::BenchArgs, settings: &crate::settings::Settings) -> Result<()> {
    let loaded = crate::load::load(&args.input, settings)?;
    let mut report = run_bench(
        &loaded.diagram,
        loaded.domain(),
        &args.input,
        &args.methods(),
        args.samples,
        args.threads,
    )?;
    if args.soa {
        report.soa = Some(run_soa_bench(
            &loaded.diagram,
            loaded.domain(),
            args.samples,
            args.threads,
        )?);
    }
    if args.json {
        println!("{}", serde_json::to_string_pretty(&report)?);
    } else {
        print!("{report}");
    }
    Ok(())
}

/// Measures every method of `methods` on `diagram` with `samples` points per measurement, the
/// batch on `threads` threads (all logical cores when `None`).
///
/// The HDS sampler is a [`HemisphereMap`] for `Domain::Hemisphere` (the diagram must lie within
/// θ ≤ 90°), else a [`SphereMap`]; the baselines are built for the same domain (the CLI passes
/// `load::domain`, so photometric files are always measured on the sphere). A method that cannot be built (for
/// example rejection sampling of a very peaked diagram) is reported with its error; only a failure
/// to set up the measurement itself is an `Err`.
pub fn run_bench(
    diagram: &Diagram,
    domain: Domain,
    label: &str,
    methods: &[Method],
    samples: usize,
    threads: Option<usize>,
) -> Result<BenchReport> {
    let samples = samples.max(1);
    let logical_cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let batch_threads = threads.unwrap_or(logical_cores).max(1);
    let load_average = std::fs::read_to_string("/proc/loadavg")
        .ok()
        .and_then(|s| s.split_whitespace().next()?.parse().ok());
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .context("building a one-thread pool")?;
    let all = rayon::ThreadPoolBuilder::new()
        .num_threads(batch_threads)
        .build()
        .context("building the batch thread pool")?;

    let hemisphere = domain == Domain::Hemisphere;
    let mut points = vec![[0.0; 2]; samples];
    Halton::with_skip(1).fill(0, &mut points);

    let mut out = Vec::with_capacity(methods.len());
    for &method in methods {
        let t0 = Instant::now();
        // Rejection is built as its own type (the sampler `Method::build` gives for it, seed 0),
        // for its acceptance rate, which only it has.
        let built: Result<(Built, Option<f64>), _> = match method {
            Method::Rejection => Rejection::new(diagram, domain).map(|r| {
                let rate = r.acceptance_rate();
                (Built::Other(Box::new(r)), Some(rate))
            }),
            _ => method.build(diagram, domain).map(|s| (s, None)),
        };
        let build_ms = t0.elapsed().as_secs_f64() * 1e3;
        let (sampler, acceptance) = match built {
            Ok(s) => s,
            Err(e) => {
                out.push(MethodBench::failed(method, e.to_string()));
                continue;
            }
        };
        out.push(measure(
            method,
            sampler.as_ref(),
            &points,
            build_ms,
            acceptance,
            &one,
            &all,
        ));
    }

    let d = diagram;
    Ok(BenchReport {
        label: label.to_owned(),
        n_parallels: d.n_parallels(),
        n_meridians: d.n_meridians(),
        domain: if hemisphere { "hemisphere" } else { "sphere" }.to_owned(),
        samples,
        paper_table_floats: gonio::mapping::paper_table_floats(d),
        machine: Machine {
            cpu_model: cpu_model(),
            logical_cores,
            batch_threads,
            single_thread_clock: if thread_cpu_ns().is_some() {
                "thread-cpu"
            } else {
                "wall"
            }
            .to_owned(),
            load_average,
        },
        methods: out,
        soa: None,
    })
}

/// Measures the HDS map's SoA batch paths (see [`SoaBench`]) with `samples` points, the
/// all-thread run on `threads` threads (all logical cores when `None`).
pub fn run_soa_bench(
    diagram: &Diagram,
    domain: Domain,
    samples: usize,
    threads: Option<usize>,
) -> Result<SoaBench> {
    let samples = samples.max(1);
    let threads = threads
        .unwrap_or(std::thread::available_parallelism().map_or(1, |n| n.get()))
        .max(1);
    let pool = |t: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(t)
            .build()
            .context("building a thread pool")
    };
    let (one, all) = (pool(1)?, pool(threads)?);
    let mut points = vec![[0.0; 2]; samples];
    Halton::with_skip(1).fill(0, &mut points);
    let u: Vec<f64> = points.iter().map(|p| p[0]).collect();
    let v: Vec<f64> = points.iter().map(|p| p[1]).collect();
    let times = |pool: &rayon::ThreadPool| -> Result<SoaTimes> {
        Ok(if domain == Domain::Hemisphere {
            let map = HemisphereMap::new(diagram)?;
            let f = map.float32_map()?;
            pool.install(|| soa_times(&map, &f, &u, &v))
        } else {
            let map = SphereMap::new(diagram)?;
            let f = map.float32_map()?;
            pool.install(|| soa_times(&map, &f, &u, &v))
        })
    };
    Ok(SoaBench {
        backend: Backend::detect().as_str().to_owned(),
        threads,
        one: times(&one)?,
        all: times(&all)?,
    })
}

/// Best of 5 wall nanoseconds per item of `f`, after one warm-up run.
fn best_wall(items: usize, mut f: impl FnMut()) -> f64 {
    f();
    (0..5)
        .map(|_| {
            let t0 = Instant::now();
            f();
            t0.elapsed().as_nanos() as f64 / items as f64
        })
        .fold(f64::INFINITY, f64::min)
}

fn soa_times<S: SoaSampler>(map: &S, f32map: &Float32Map, u: &[f64], v: &[f64]) -> SoaTimes {
    let (f64s, dirs) = soa_type(map, u.to_vec(), v.to_vec(), None);
    let dirs32: Vec<Vec<f32>> = dirs
        .iter()
        .map(|c| c.iter().map(|&x| x as f32).collect())
        .collect();
    let u32s: Vec<f32> = u.iter().map(|&x| x as f32).collect();
    let v32s: Vec<f32> = v.iter().map(|&x| x as f32).collect();
    let (f32s, _) = soa_type(map, u32s.clone(), v32s.clone(), Some(dirs32.clone()));
    let own = float32_times(f32map, &u32s, &v32s, &dirs32);
    SoaTimes {
        forward_float32_ns: own[0],
        pdf_float32_ns: own[1],
        inverse_float32_ns: own[2],
        forward_f64_ns: f64s[0],
        pdf_f64_ns: f64s[1],
        inverse_f64_ns: f64s[2],
        forward_f32_ns: f32s[0],
        pdf_f32_ns: f32s[1],
        inverse_f32_ns: f32s[2],
    }
}

/// Forward, pdf and inverse times of the float32 map (pdf and inverse on `dirs`).
fn float32_times(map: &Float32Map, u: &[f32], v: &[f32], dirs: &[Vec<f32>]) -> [f64; 3] {
    let n = u.len();
    let mut o = vec![vec![0f32; n]; 4];
    let forward = {
        let [x, y, z, p] = &mut o[..] else {
            unreachable!("four columns")
        };
        best_wall(n, || {
            map.batch_par(Soa::Sample {
                u: black_box(u),
                v,
                dir: [&mut *x, &mut *y, &mut *z],
                pdf: &mut *p,
            });
        })
    };
    let d = dirs;
    let mut pdf = vec![0f32; n];
    let pdf_ns = best_wall(n, || {
        map.batch_par(Soa::Pdf {
            dir: [black_box(&d[0]), &d[1], &d[2]],
            pdf: &mut pdf,
        })
    });
    let (mut wu, mut wv) = (vec![0f32; n], vec![0f32; n]);
    // The kernels' inverse alone (as the f64 columns' `invert_soa_par`), on the one parallel
    // driver.
    let inverse = best_wall(n, || {
        let job = Soa::Invert {
            dir: [black_box(&d[0]), &d[1], &d[2]],
            uv: [&mut wu, &mut wv],
        };
        gonio::batch::par(job, &|j| {
            if let Soa::Invert { dir, uv } = j {
                map.invert_soa(dir, uv)
            }
        })
    });
    [forward, pdf_ns, inverse]
}

/// Forward, pdf and inverse times in the element type T; pdf and inverse on `dirs` when given,
/// else on the forward map's own directions (which are returned).
fn soa_type<S: SoaSampler, T: BatchFloat>(
    map: &S,
    u: Vec<T>,
    v: Vec<T>,
    dirs: Option<Vec<Vec<T>>>,
) -> ([f64; 3], Vec<Vec<T>>) {
    let n = u.len();
    let mut o = vec![vec![u[0]; n]; 4];
    let forward = {
        let [x, y, z, p] = &mut o[..] else {
            unreachable!("four columns")
        };
        best_wall(n, || {
            sample_soa_par(map, black_box(&u), &v, [&mut *x, &mut *y, &mut *z], &mut *p);
        })
    };
    o.truncate(3);
    let d = dirs.unwrap_or(o);
    let mut pdf = vec![u[0]; n];
    let pdf_ns = best_wall(n, || {
        pdf_soa_par(map, [black_box(&d[0]), &d[1], &d[2]], &mut pdf)
    });
    let (mut wu, mut wv) = (vec![u[0]; n], vec![u[0]; n]);
    let inverse = best_wall(n, || {
        invert_soa_par(map, [black_box(&d[0]), &d[1], &d[2]], [&mut wu, &mut wv])
    });
    ([forward, pdf_ns, inverse], d)
}

impl MethodBench {
    fn failed(method: Method, error: String) -> Self {
        MethodBench {
            method: method.to_string(),
            error: Some(error),
            build_ms: None,
            memory_bytes: None,
            forward_ns: None,
            inverse_ns: None,
            pdf_ns: None,
            batch_one_thread_ns: None,
            batch_all_threads_ns: None,
            batch_scaling: None,
            batch_cpu_ratio: None,
            acceptance: None,
        }
    }
}

fn measure(
    method: Method,
    s: &dyn Sampler,
    points: &[Point2],
    build_ms: f64,
    acceptance: Option<f64>,
    one: &rayon::ThreadPool,
    all: &rayon::ThreadPool,
) -> MethodBench {
    let n = points.len();
    let mut samples = vec![Sample::default(); n];
    let forward = per_item_cpu(REPEATS, n, || {
        s.sample_batch(black_box(points), &mut samples);
        black_box(&samples);
    });
    let dirs: Vec<Vec3> = samples.iter().map(|x| x.direction).collect();
    let mut pdfs = vec![0.0; n];
    let pdf = per_item_cpu(REPEATS, n, || {
        s.pdf_batch(black_box(&dirs), &mut pdfs);
        black_box(&pdfs);
    });
    let has_inverse = s.invert(dirs[0]) != Err(gonio::InvertError::Unsupported);
    let mut inverted = vec![Ok([0.0; 2]); n];
    let inverse = has_inverse.then(|| {
        per_item_cpu(REPEATS, n, || {
            s.invert_batch(black_box(&dirs), &mut inverted);
            black_box(&inverted);
        })
    });
    // The batch functions split the work into chunks of 4096 points: give them at least
    // MIN_BATCH points (the same points, repeated) so that every thread has several chunks.
    let big: Vec<Point2> = points
        .iter()
        .copied()
        .cycle()
        .take(n.max(MIN_BATCH))
        .collect();
    let mut big_out = vec![Sample::default(); big.len()];
    let mut batch = |pool: &rayon::ThreadPool| {
        pool.install(|| {
            per_item_wall(BATCH_REPEATS, big.len(), || {
                sample_batch_par(s, black_box(&big), &mut big_out);
                black_box(&big_out);
            })
        })
    };
    let (b1, c1) = batch(one);
    let (bn, cn) = batch(all);
    MethodBench {
        method: method.to_string(),
        error: None,
        build_ms: Some(build_ms),
        memory_bytes: Some(s.memory_bytes()),
        forward_ns: Some(forward),
        inverse_ns: inverse,
        pdf_ns: Some(pdf),
        batch_one_thread_ns: Some(b1),
        batch_all_threads_ns: Some(bn),
        batch_scaling: Some(b1 / bn),
        batch_cpu_ratio: (c1 / cn).is_finite().then_some(c1 / cn),
        acceptance,
    }
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    let k = v.len();
    if k % 2 == 1 {
        v[k / 2]
    } else {
        0.5 * (v[k / 2 - 1] + v[k / 2])
    }
}

/// Median thread-CPU (else wall) nanoseconds per item of `f`, after one warm-up run.
fn per_item_cpu(repeats: usize, items: usize, mut f: impl FnMut()) -> f64 {
    f();
    median(
        (0..repeats)
            .map(|_| {
                let (c0, t0) = (thread_cpu_ns(), Instant::now());
                f();
                let wall = t0.elapsed().as_nanos() as f64;
                match (c0, thread_cpu_ns()) {
                    (Some(a), Some(b)) => b.saturating_sub(a) as f64 / items as f64,
                    _ => wall / items as f64,
                }
            })
            .collect(),
    )
}

/// Median wall nanoseconds per item of `f` and median process-CPU nanoseconds per item (all
/// threads together; `NaN` where unavailable), after one warm-up run.
fn per_item_wall(repeats: usize, items: usize, mut f: impl FnMut()) -> (f64, f64) {
    f();
    let (wall, cpu): (Vec<f64>, Vec<f64>) = (0..repeats)
        .map(|_| {
            let (c0, t0) = (process_cpu_ns(), Instant::now());
            f();
            let wall = t0.elapsed().as_nanos() as f64 / items as f64;
            let cpu = match (c0, process_cpu_ns()) {
                (Some(a), Some(b)) => b.saturating_sub(a) as f64 / items as f64,
                _ => f64::NAN,
            };
            (wall, cpu)
        })
        .unzip();
    (median(wall), median(cpu))
}

fn cpu_model() -> Option<String> {
    let text = std::fs::read_to_string("/proc/cpuinfo").ok()?;
    text.lines()
        .find(|l| l.starts_with("model name"))
        .and_then(|l| l.split(':').nth(1))
        .map(|s| s.trim().to_owned())
}

fn cell(x: Option<f64>, digits: usize) -> String {
    x.map_or_else(|| "—".to_owned(), |v| format!("{v:.digits$}"))
}

impl fmt::Display for BenchReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let m = &self.machine;
        writeln!(
            f,
            "{}: {} parallels × {} meridians ({}), {} points per measurement",
            self.label, self.n_parallels, self.n_meridians, self.domain, self.samples
        )?;
        writeln!(
            f,
            "machine: {}, {} logical cores, batch on {} threads, one-thread clock: {}{}",
            m.cpu_model.as_deref().unwrap_or("unknown CPU"),
            m.logical_cores,
            m.batch_threads,
            m.single_thread_clock,
            m.load_average
                .map_or(String::new(), |l| format!(", load average {l:.2}"))
        )?;
        writeln!(
            f,
            "paper's table size for this grid: M·N + 2M + 2 = {} floats ({:.1} KiB as f64)",
            self.paper_table_floats,
            self.paper_table_floats as f64 * 8.0 / 1024.0
        )?;
        let header = [
            "method",
            "build ms",
            "memory KiB",
            "forward ns",
            "inverse ns",
            "pdf ns",
            "batch 1 thr ns",
            "batch all ns",
            "scaling",
            "cpu ratio",
            "acceptance",
        ];
        // Ok(cells) for a measured method, Err((name, error)) for one that could not be built.
        let rows: Vec<Result<Vec<String>, (String, String)>> = self
            .methods
            .iter()
            .map(|r| match &r.error {
                Some(e) => Err((r.method.clone(), e.clone())),
                None => Ok(vec![
                    r.method.clone(),
                    cell(r.build_ms, 2),
                    cell(r.memory_bytes.map(|b| b as f64 / 1024.0), 1),
                    cell(r.forward_ns, 1),
                    cell(r.inverse_ns, 1),
                    cell(r.pdf_ns, 1),
                    cell(r.batch_one_thread_ns, 1),
                    cell(r.batch_all_threads_ns, 1),
                    cell(r.batch_scaling, 2),
                    cell(r.batch_cpu_ratio, 2),
                    cell(r.acceptance, 4),
                ]),
            })
            .collect();
        let widths: Vec<usize> = (0..header.len())
            .map(|c| {
                rows.iter()
                    .filter_map(|r| r.as_ref().ok())
                    .map(|r| r[c].chars().count())
                    .chain([header[c].chars().count()])
                    .max()
                    .unwrap_or(0)
            })
            .collect();
        let line = |cells: &[String]| -> String {
            cells
                .iter()
                .zip(&widths)
                .enumerate()
                .map(|(c, (s, &w))| {
                    if c == 0 {
                        format!("{s:<w$}")
                    } else {
                        format!("{s:>w$}")
                    }
                })
                .collect::<Vec<_>>()
                .join("  ")
        };
        let head: Vec<String> = header.iter().map(|s| s.to_string()).collect();
        writeln!(f, "{}", line(&head))?;
        for r in &rows {
            match r {
                Ok(cells) => writeln!(f, "{}", line(cells))?,
                Err((name, e)) => writeln!(f, "{name:<w$}  not built: {e}", w = widths[0])?,
            }
        }
        if let Some(soa) = &self.soa {
            writeln!(
                f,
                "hds SoA batch paths ({}), wall ns per point, best of 5:",
                soa.backend
            )?;
            writeln!(
                f,
                "threads  forward f64  pdf f64  inverse f64  forward f32  pdf f32  inverse f32  \
                 float32 map: forward  pdf  inverse"
            )?;
            for (t, r) in [(1, &soa.one), (soa.threads, &soa.all)] {
                writeln!(
                    f,
                    "{t:>7}  {:>11.1}  {:>7.1}  {:>11.1}  {:>11.1}  {:>7.1}  {:>11.1}  \
                     {:>20.1}  {:>3.1}  {:>7.1}",
                    r.forward_f64_ns,
                    r.pdf_f64_ns,
                    r.inverse_f64_ns,
                    r.forward_f32_ns,
                    r.pdf_f32_ns,
                    r.inverse_f32_ns,
                    r.forward_float32_ns,
                    r.pdf_float32_ns,
                    r.inverse_float32_ns
                )?;
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn report_has_every_method_and_serialises() {
        let d =
            gonio::synthetic::random_hemisphere(gonio::synthetic::Family::Lobes, 7, 8, false, 1);
        let r = run_bench(&d, Domain::Hemisphere, "toy", &Method::ALL, 512, Some(2)).unwrap();
        assert_eq!(r.methods.len(), Method::ALL.len());
        for m in &r.methods {
            assert!(m.error.is_some() || m.forward_ns.unwrap() > 0.0, "{m:?}");
        }
        let hds = &r.methods[0];
        assert!(hds.inverse_ns.is_some() && hds.memory_bytes.unwrap() > 0);
        let rej = r.methods.iter().find(|m| m.method == "rejection").unwrap();
        assert!(rej.error.is_some() || rej.acceptance.is_some() && rej.inverse_ns.is_none());
        let json = serde_json::to_string(&r).unwrap();
        assert!(json.contains("\"forward_ns\""));
        let text = r.to_string();
        println!("{text}");
        assert!(text.contains("hds") && text.contains("forward ns"));
    }

    #[test]
    fn sphere_diagram_uses_the_sphere_domain() {
        let d = gonio::synthetic::example_luminaire();
        let r = run_bench(
            &d,
            Domain::Sphere,
            "example",
            &[Method::Hds, Method::Uniform],
            256,
            Some(1),
        )
        .unwrap();
        assert_eq!(r.domain, "sphere");
        assert!(r.methods.iter().all(|m| m.error.is_none()));
    }
}
