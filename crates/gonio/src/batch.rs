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

/// One structure-of-arrays batch call with elements of type `T` (f64 or f32): the one shape in
/// which every batch reaches a sampler ([`crate::Sampler::batch`]). Entry `k` of every slice
/// belongs to point `k`; every slice of one call has the same length.
///
/// Conventions, as in [`crate::Sampler`]: directions are unit vectors in the sampler's frame,
/// densities per steradian, points of the square in [0, 1]². An inverse with no preimage
/// (outside the domain, density 0, no inverse at all) writes NaN to both coordinates.
#[derive(Debug)]
pub enum Soa<'a, T> {
    /// Map the points `(u[k], v[k])` to directions `dir[·][k]` and their exact densities `pdf[k]`.
    Sample {
        /// First coordinates of the points of the square.
        u: &'a [T],
        /// Second coordinates.
        v: &'a [T],
        /// Out: the directions' x, y and z.
        dir: [&'a mut [T]; 3],
        /// Out: the densities, per steradian.
        pdf: &'a mut [T],
    },
    /// The density at each direction `dir[·][k]` into `pdf[k]`; 0 outside the domain.
    Pdf {
        /// The directions' x, y and z.
        dir: [&'a [T]; 3],
        /// Out: the densities, per steradian.
        pdf: &'a mut [T],
    },
    /// The point of the square of each direction `dir[·][k]` into `(uv[0][k], uv[1][k])`, NaN
    /// in both where there is none.
    Invert {
        /// The directions' x, y and z.
        dir: [&'a [T]; 3],
        /// Out: the points' u and v.
        uv: [&'a mut [T]; 2],
    },
}

/// A batch call in either precision: what [`crate::Sampler::batch`] takes. `F32` is the float32
/// path: a sampler with a float32 map (the HDS maps) runs it in f32; every other one evaluates it
/// in f64 and rounds each result once.
#[derive(Debug)]
pub enum Batch<'a> {
    /// A float64 call.
    F64(Soa<'a, f64>),
    /// A float32 call.
    F32(Soa<'a, f32>),
}

impl<'a> From<Soa<'a, f64>> for Batch<'a> {
    fn from(s: Soa<'a, f64>) -> Self {
        Batch::F64(s)
    }
}

impl<'a> From<Soa<'a, f32>> for Batch<'a> {
    fn from(s: Soa<'a, f32>) -> Self {
        Batch::F32(s)
    }
}

impl<'a, T> Soa<'a, T> {
    /// The number of points of the call.
    ///
    /// # Panics
    /// If its slices differ in length (a programming error of the caller, not an input error).
    pub fn len(&self) -> usize {
        match self {
            Soa::Sample { u, v, dir, pdf } => {
                let lens = [v.len(), dir[0].len(), dir[1].len(), dir[2].len(), pdf.len()];
                check_len("sample", u.len(), &lens);
                u.len()
            }
            Soa::Pdf { dir, pdf } => {
                check_len(
                    "pdf",
                    pdf.len(),
                    &[dir[0].len(), dir[1].len(), dir[2].len()],
                );
                pdf.len()
            }
            Soa::Invert { dir, uv } => {
                let lens = [uv[1].len(), dir[0].len(), dir[1].len(), dir[2].len()];
                check_len("invert", uv[0].len(), &lens);
                uv[0].len()
            }
        }
    }

    /// Whether the call has no points.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The call on points `0..mid` and the call on points `mid..` (for splitting a batch into
    /// tasks).
    ///
    /// # Panics
    /// If `mid` exceeds [`Soa::len`].
    pub fn split_at(self, mid: usize) -> (Self, Self) {
        fn cut<T>(s: &[T], m: usize) -> (&[T], &[T]) {
            s.split_at(m)
        }
        fn cut_mut<T>(s: &mut [T], m: usize) -> (&mut [T], &mut [T]) {
            s.split_at_mut(m)
        }
        fn cut3<T>(d: [&[T]; 3], m: usize) -> ([&[T]; 3], [&[T]; 3]) {
            let [(a0, b0), (a1, b1), (a2, b2)] = d.map(|s| cut(s, m));
            ([a0, a1, a2], [b0, b1, b2])
        }
        match self {
            Soa::Sample { u, v, dir, pdf } => {
                let [x, y, z] = dir;
                let ((u0, u1), (v0, v1)) = (cut(u, mid), cut(v, mid));
                let ((x0, x1), (y0, y1), (z0, z1)) =
                    (cut_mut(x, mid), cut_mut(y, mid), cut_mut(z, mid));
                let (p0, p1) = cut_mut(pdf, mid);
                (
                    Soa::Sample {
                        u: u0,
                        v: v0,
                        dir: [x0, y0, z0],
                        pdf: p0,
                    },
                    Soa::Sample {
                        u: u1,
                        v: v1,
                        dir: [x1, y1, z1],
                        pdf: p1,
                    },
                )
            }
            Soa::Pdf { dir, pdf } => {
                let (d0, d1) = cut3(dir, mid);
                let (p0, p1) = cut_mut(pdf, mid);
                (Soa::Pdf { dir: d0, pdf: p0 }, Soa::Pdf { dir: d1, pdf: p1 })
            }
            Soa::Invert { dir, uv } => {
                let (d0, d1) = cut3(dir, mid);
                let [u, v] = uv;
                let ((u0, u1), (v0, v1)) = (cut_mut(u, mid), cut_mut(v, mid));
                (
                    Soa::Invert {
                        dir: d0,
                        uv: [u0, v0],
                    },
                    Soa::Invert {
                        dir: d1,
                        uv: [u1, v1],
                    },
                )
            }
        }
    }
}

impl Batch<'_> {
    /// The number of points of the call ([`Soa::len`]).
    ///
    /// # Panics
    /// If its slices differ in length.
    pub fn len(&self) -> usize {
        match self {
            Batch::F64(s) => s.len(),
            Batch::F32(s) => s.len(),
        }
    }

    /// Whether the call has no points.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// [`Soa::split_at`] in either precision.
    pub fn split_at(self, mid: usize) -> (Self, Self) {
        match self {
            Batch::F64(s) => {
                let (a, b) = s.split_at(mid);
                (Batch::F64(a), Batch::F64(b))
            }
            Batch::F32(s) => {
                let (a, b) = s.split_at(mid);
                (Batch::F32(a), Batch::F32(b))
            }
        }
    }
}

mod sealed {
    pub trait Sealed {}
    impl Sealed for f64 {}
    impl Sealed for f32 {}
}

/// The element types of a batch call, f64 and f32: code generic over the precision (the Python
/// package's and the C ABI's batches) makes its call with `sampler.batch(T::call(job))`.
pub trait Element: Copy + Send + Sync + sealed::Sealed + 'static {
    /// `job` as a call in either precision.
    fn call(job: Soa<'_, Self>) -> Batch<'_>;
}

impl Element for f64 {
    fn call(job: Soa<'_, f64>) -> Batch<'_> {
        Batch::F64(job)
    }
}

impl Element for f32 {
    fn call(job: Soa<'_, f32>) -> Batch<'_> {
        Batch::F32(job)
    }
}

/// Something a parallel batch splits into tasks: a length and a cut.
pub trait Split: Sized + Send {
    /// The number of points.
    fn points(&self) -> usize;
    /// The points `0..mid` and `mid..`.
    fn split_at(self, mid: usize) -> (Self, Self);
}

impl Split for Batch<'_> {
    fn points(&self) -> usize {
        Batch::len(self)
    }
    fn split_at(self, mid: usize) -> (Self, Self) {
        Batch::split_at(self, mid)
    }
}

impl<T: Send + Sync> Split for Soa<'_, T> {
    fn points(&self) -> usize {
        Soa::len(self)
    }
    fn split_at(self, mid: usize) -> (Self, Self) {
        Soa::split_at(self, mid)
    }
}

impl<A: Sync, B: Send> Split for (&[A], &mut [B]) {
    fn points(&self) -> usize {
        check_len("batch", self.0.len(), &[self.1.len()]);
        self.0.len()
    }
    fn split_at(self, mid: usize) -> (Self, Self) {
        let (a0, a1) = self.0.split_at(mid);
        let (b0, b1) = self.1.split_at_mut(mid);
        ((a0, b0), (a1, b1))
    }
}

/// The one parallel driver of every batch of the project: `job` cut into tasks of at most
/// [`PAR_CHUNK`] points (halving, on rayon's pool), `run` called on each. Each output depends only
/// on its own input, so the result does not depend on the number of threads.
pub fn par<J: Split, F: Fn(J) + Sync>(job: J, run: &F) {
    let n = job.points();
    if n <= PAR_CHUNK {
        run(job);
        return;
    }
    // Cut on a multiple of PAR_CHUNK, so that the tasks are those of `par_chunks(PAR_CHUNK)`.
    let mid = n.div_ceil(2 * PAR_CHUNK) * PAR_CHUNK;
    let (a, b) = job.split_at(mid);
    rayon::join(|| par(a, run), || par(b, run));
}
