//! Sequences, the check battery, conversion and writing.

use crate::arrays;
use crate::diagram::{dumps, out_format};
use crate::sampler::PySampler;
use crate::types::PyDiagram;
use crate::{detached, InputError};
use gonio::check::{cell_boundary_points, run_battery_with_progress, BatteryOptions};
use gonio::sequence::{Sequence, SequenceKind};
use gonio::Method;
use gonio::Point2;
use numpy::PyArray2;
use pyo3::prelude::*;
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};

/// Largest number of points `sequence` makes in one call (2 GiB of float64).
const MAX_POINTS: u64 = 1 << 27;

/// Points of the unit square [0, 1)², shape (n, 2): `kind` "halton" (bases 2, 3; deterministic,
/// `seed` ignored), "sobol" (Owen-scrambled Sobol' seeded with `seed`) or "random" (iid,
/// Xoshiro256++ seeded with `seed`), points number `start` … `start + n − 1`. The same points as
/// the CLI's `gonio sample --sequence KIND --seed SEED`.
#[pyfunction]
#[pyo3(signature = (n, kind = "halton", seed = 0, start = 0))]
pub(crate) fn sequence<'py>(
    py: Python<'py>,
    n: u64,
    kind: &str,
    seed: u64,
    start: u64,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let kind: SequenceKind = kind
        .parse()
        .map_err(|e: gonio::sequence::UnknownSequence| InputError::new_err(e.to_string()))?;
    if n > MAX_POINTS {
        return Err(InputError::new_err(format!(
            "n = {n} points is more than the limit of {MAX_POINTS} per call; ask in batches with `start`"
        )));
    }
    if start.checked_add(n).is_none() {
        return Err(InputError::new_err(format!(
            "start + n = {start} + {n} overflows the sequence index"
        )));
    }
    let seq = Sequence::new(kind, seed);
    let n = n as usize;
    let arr = arrays::zeros::<f64, numpy::Ix2>(py, &[n, 2])?;
    arrays::fill(&arr, "sequence", |flat| {
        let (pts, _) = flat.as_chunks_mut::<2>();
        crate::batch::in_slices(py, "sequence", n, |r| {
            seq.fill_par(start + r.start as u64, &mut pts[r]);
            None
        })
    })?;
    Ok(arr)
}

/// The names of every sampling method, as `Sampler(method=...)` accepts them.
#[pyfunction]
pub(crate) fn methods() -> Vec<&'static str> {
    Method::ALL.iter().map(|m| m.as_str()).collect()
}

/// Runs the test battery of `gonio check` on the sampler of `method` for `diagram` (chi-square,
/// round trip, pdf consistency, normalisation, pdf/target ratio, flux) and returns its report as
/// a dict, the same as `gonio check --json` prints (`report["passed"]` is the verdict). `quick`
/// runs the cheaper settings of `gonio check --quick`; `samples` overrides the chi-square and
/// flux sample counts; `seed` seeds every item.
#[pyfunction]
#[pyo3(signature = (diagram, method = "hds", *, samples = None, seed = 0, quick = false, progress = None))]
pub(crate) fn check<'py>(
    py: Python<'py>,
    diagram: &Bound<'py, PyDiagram>,
    method: &str,
    samples: Option<usize>,
    seed: u64,
    quick: bool,
    progress: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyAny>> {
    let progress = crate::progress::Progress::new(py, progress, "check")?;
    let mut opts = if quick {
        BatteryOptions::quick()
    } else {
        BatteryOptions::default()
    }
    .with_seed(seed);
    if let Some(n) = samples {
        if n == 0 {
            return Err(InputError::new_err("samples must be positive"));
        }
        opts.chi_square.samples = n;
        opts.flux.samples = n;
    }
    let s = PySampler::build(diagram, method, None, None, None, None)?;
    // The map claims its guaranteed bound; the flux check integrates the diagram's power.
    opts.ratio.claimed_bound = s.ratio_bound_value();
    opts.flux_total = s.target_power_value();
    let d = &diagram.get().diagram;
    let json = interruptible(py, "check", Some(&progress), |stop, state| {
        opts.round_trip.extra_points =
            cell_boundary_points(s.inner(), d, if quick { 16 } else { 64 });
        // The battery reports its progress after every chunk of samples: there a pending
        // Ctrl-C (or an exception of the progress callable) ends it (unwinding with a payload
        // that is no panic, so no hook prints), and the latest (item, fraction) is left for the
        // calling thread to report.
        let report = run_battery_with_progress(s.inner(), &opts, &|item, fraction| {
            if stop.load(Ordering::Relaxed) {
                std::panic::resume_unwind(Box::new(Interrupted));
            }
            if let Ok(mut st) = state.lock() {
                *st = Some((item.to_string(), fraction));
            }
        });
        serde_json::to_string(&report)
    })?
    .map_err(|e| InputError::new_err(e.to_string()))?;
    py.import("json")?.call_method1("loads", (json,))
}

/// The payload that ends an [`interruptible`] computation early.
struct Interrupted;

/// The latest progress a worker left for the calling thread: (item, fraction).
type ProgressState = std::sync::Mutex<Option<(String, f64)>>;

/// Runs `f` on a worker thread while this thread, GIL released, handles signals every 10 ms:
/// when a signal handler raises (Ctrl-C: KeyboardInterrupt), `stop` is set, the worker ends at
/// its next check and the exception is returned. A panic of `f` becomes InternalError. The
/// progress `f` leaves in its state is reported to `progress` from this thread (an exception of
/// the callable stops the worker as a signal does).
fn interruptible<T: Send>(
    py: Python<'_>,
    what: &str,
    progress: Option<&crate::progress::Progress<'_>>,
    f: impl FnOnce(&AtomicBool, &ProgressState) -> T + Send,
) -> PyResult<T> {
    let stop = AtomicBool::new(false);
    let state: ProgressState = std::sync::Mutex::new(None);
    std::thread::scope(|scope| {
        let worker = scope
            .spawn(|| std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| f(&stop, &state))));
        let mut signal = None;
        let mut last: Option<(String, f64)> = None;
        while !worker.is_finished() {
            py.detach(|| std::thread::sleep(std::time::Duration::from_millis(10)));
            if signal.is_none() {
                if let Err(e) = py.check_signals() {
                    stop.store(true, Ordering::Relaxed);
                    signal = Some(e);
                }
            }
            if let (None, Some(p)) = (&signal, progress.filter(|p| p.active())) {
                let now = state.lock().ok().and_then(|s| s.clone());
                if let Some((item, fraction)) = now.as_ref().filter(|_| now != last) {
                    if let Err(e) = p.report(item, *fraction) {
                        stop.store(true, Ordering::Relaxed);
                        signal = Some(e);
                    }
                    last = now;
                }
            }
        }
        if let (None, Some(p)) = (&signal, progress.filter(|p| p.active())) {
            if let Err(e) = p.report("done", 1.0) {
                signal = Some(e);
            }
        }
        let result = py.detach(|| worker.join());
        if let Some(e) = signal {
            return Err(e);
        }
        match result {
            Ok(Ok(v)) => Ok(v),
            Ok(Err(p)) | Err(p) => Err(crate::panic_error(what, p)),
        }
    })
}

/// Converts a file as `gonio convert IN OUT` does: reads `src` (.json, .ies, .ldt) and writes
/// `dst` in the format of its extension (JSON, IES LM-63-2019 or EULUMDAT), the luminaire named
/// after `src`'s file stem.
#[pyfunction]
pub(crate) fn convert(py: Python<'_>, src: PathBuf, dst: PathBuf) -> PyResult<()> {
    let fmt = out_format(&dst, None)?;
    let d = crate::diagram::read(py, src, None)?;
    let d = d.get();
    let text = dumps(&d.diagram, &fmt, d.stem())?;
    std::fs::write(&dst, text).map_err(|e| {
        pyo3::exceptions::PyOSError::new_err(format!("cannot write {}: {e}", dst.display()))
    })
}

/// Panics inside the library's thread pool with the GIL released (`detached = True`) or
/// while holding it, to test that no panic crosses into Python (InternalError instead).
#[pyfunction]
#[pyo3(name = "_panic_for_test", signature = (detached = true))]
pub(crate) fn panic_for_test(py: Python<'_>, detached: bool) -> PyResult<()> {
    use rayon::prelude::*;
    let f = || {
        (0..64u32).into_par_iter().for_each(|i| {
            if i == 37 {
                panic!("deliberate panic for the test of panic safety");
            }
        })
    };
    if detached {
        crate::detached(py, "_panic_for_test", f)
    } else {
        crate::no_panic("_panic_for_test", f)
    }
}

/// The reference of the speed comparison (docs/PYTHON.md, "Speed"): the best wall time in
/// seconds, over `runs` runs, of the library's own batch call `gonio::sampler::sample_batch_par`
/// on the points `u` (n, 2) into a preallocated `Vec<Sample>`, timed inside Rust around that call
/// only (the points are converted before). `Sampler.sample` on the same points does the same work
/// plus the numpy conversions and allocations.
#[pyfunction]
#[pyo3(name = "_bench_rust_batch", signature = (sampler, u, runs = 10))]
pub(crate) fn bench_rust_batch(
    py: Python<'_>,
    sampler: &Bound<'_, PySampler>,
    u: &Bound<'_, PyAny>,
    runs: usize,
) -> PyResult<f64> {
    let rows = arrays::rows::<2>(u, "u")?;
    let pts: Vec<Point2> = rows.as_slice().into_owned();
    let s = sampler.get().inner();
    detached(py, "_bench_rust_batch", || {
        let mut out = vec![gonio::Sample::default(); pts.len()];
        let mut best = f64::INFINITY;
        for _ in 0..runs.max(1) {
            let t = std::time::Instant::now();
            gonio::sampler::sample_batch_par(s, &pts, &mut out);
            best = best.min(t.elapsed().as_secs_f64());
            std::hint::black_box(&out);
        }
        best
    })
}

/// The kind of file named `kind` ("photometry", "diagram", "tilt", "image", "brdf", "mesh",
/// "tables").
fn file_kind(kind: &str) -> PyResult<gonio::input::file::FileKind> {
    gonio::input::file::FileKind::from_name(kind).ok_or_else(|| {
        crate::InputError::new_err(format!(
            "kind: {kind:?} is not one of \"photometry\", \"diagram\", \"tilt\", \"image\", \"brdf\", \"mesh\", \"tables\""
        ))
    })
}

/// The size limit in bytes of files of `kind` that every gonio front end (CLI, C, Python) reads:
/// the value `set_read_limit` set, else the default (photometry and diagram 64 MiB, tilt 4 MiB,
/// image 4 GiB, brdf 256 MiB, mesh 2 GiB, tables 4 GiB).
#[pyfunction]
pub(crate) fn read_limit(kind: &str) -> PyResult<u64> {
    Ok(gonio::input::file::read_limit(file_kind(kind)?))
}

/// Sets the size limit in bytes of files of `kind` for the whole process (0 restores the
/// default). A larger file is refused before it is read.
#[pyfunction]
pub(crate) fn set_read_limit(kind: &str, bytes: u64) -> PyResult<()> {
    gonio::input::file::set_read_limit(file_kind(kind)?, bytes);
    Ok(())
}
