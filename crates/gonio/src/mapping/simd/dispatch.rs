//! The choice of backend for one batch call on one HDS map, and the f32 calls' widening to the
//! f64 kernels (rounded once). Everything above this file (the maps' [`crate::mapping::batch`]
//! impls) sees three functions: [`core_sample`], [`core_density`], [`core_invert`].

use super::{portable, Backend, Elem};
use crate::mapping::hds::{HdsCore, TablesView};

// Points per chunk when an f32 call runs through the f64 kernels.
use crate::batch::CHUNK as F32_CHUNK;

/// The `f64` slice a `T` slice is, when `T` is f64 (the batch paths run f64 kernels only).
fn as_f64<T: Elem>(s: &[T]) -> Option<&[f64]> {
    (std::any::TypeId::of::<T>() == std::any::TypeId::of::<f64>())
        // SAFETY: T is f64 (checked just above): same layout, same length.
        .then(|| unsafe { std::slice::from_raw_parts(s.as_ptr().cast::<f64>(), s.len()) })
}

/// [`as_f64`] for a mutable slice.
fn as_f64_mut<T: Elem>(s: &mut [T]) -> Option<&mut [f64]> {
    (std::any::TypeId::of::<T>() == std::any::TypeId::of::<f64>())
        // SAFETY: T is f64 (checked just above): same layout, same length, borrowed uniquely.
        .then(|| unsafe { std::slice::from_raw_parts_mut(s.as_mut_ptr().cast::<f64>(), s.len()) })
}

/// `T` values widened into the first `cnt` entries of an f64 buffer.
fn widen<T: Elem>(src: &[T], buf: &mut [f64; F32_CHUNK]) {
    for (b, &x) in buf.iter_mut().zip(src) {
        *b = x.to_f64();
    }
}

/// Renormalises the first `cnt` widened f32 directions in f64 ([`crate::batch::renormalise`]: the
/// one rule of every f32 batch call).
fn renormalise(d: &mut [[f64; F32_CHUNK]; 3], cnt: usize) {
    let [x, y, z] = d;
    crate::batch::renormalise([&mut x[..], &mut y[..], &mut z[..]], cnt);
}

/// f64 values rounded into `T`.
fn narrow<T: Elem>(src: &[f64], dst: &mut [T]) {
    for (d, &x) in dst.iter_mut().zip(src) {
        *d = T::from_f64(x);
    }
}

/// The backend that runs an f64 call: `b` if the CPU has it (else the fastest below it), and the
/// portable one for a map too large for the explicit kernels' 32-bit index conversions.
fn backend_for(b: Backend, c: &HdsCore) -> Backend {
    let b = b.usable();
    #[cfg(target_arch = "x86_64")]
    if b != Backend::Portable && !c.explicit_indexable() {
        return Backend::Portable;
    }
    let _ = c;
    b
}

/// The forward map of `c` on slices: directions to `out[0..3]`, the disk density D to `out[3]`.
pub(crate) fn core_sample<T: Elem>(b: Backend, c: &HdsCore, u: &[T], v: &[T], out: [&mut [T]; 4]) {
    let (Some(u), Some(v)) = (as_f64(u), as_f64(v)) else {
        let mut o = out;
        let (mut bu, mut bv) = ([0.0; F32_CHUNK], [0.0; F32_CHUNK]);
        let mut bo = [[0.0; F32_CHUNK]; 4];
        let mut start = 0;
        while start < u.len() {
            let cnt = (u.len() - start).min(F32_CHUNK);
            widen(&u[start..start + cnt], &mut bu);
            widen(&v[start..start + cnt], &mut bv);
            let [bx, by, bz, bd] = &mut bo;
            core_sample::<f64>(
                b,
                c,
                &bu[..cnt],
                &bv[..cnt],
                [
                    &mut bx[..cnt],
                    &mut by[..cnt],
                    &mut bz[..cnt],
                    &mut bd[..cnt],
                ],
            );
            for (col, bcol) in o.iter_mut().zip(&bo) {
                narrow(&bcol[..cnt], &mut col[start..start + cnt]);
            }
            start += cnt;
        }
        return;
    };
    let out = out.map(|o| as_f64_mut(o).expect("T is f64"));
    match backend_for(b, c) {
        // SAFETY (both): `backend_for` returns a backend only when the CPU has its instruction
        // set (`Backend::usable`).
        #[cfg(target_arch = "x86_64")]
        Backend::Avx512 => unsafe { super::avx512::k2::sample_slices(&c.view(), u, v, out) },
        #[cfg(target_arch = "x86_64")]
        Backend::Avx2Fma => unsafe { super::avx2::sample_slices(&c.view(), u, v, out) },
        _ => portable::sample_slices(&c.view(), u, v, out),
    }
}

/// The disk density D of `c` at each direction; the caller handles directions outside the map's
/// hemisphere.
pub(crate) fn core_density<T: Elem>(b: Backend, c: &HdsCore, dir: [&[T]; 3], out: &mut [T]) {
    let (Some(x), Some(y), Some(z)) = (as_f64(dir[0]), as_f64(dir[1]), as_f64(dir[2])) else {
        let mut bd = [[0.0; F32_CHUNK]; 3];
        let mut bo = [0.0; F32_CHUNK];
        let mut start = 0;
        while start < out.len() {
            let cnt = (out.len() - start).min(F32_CHUNK);
            for (k, b) in bd.iter_mut().enumerate() {
                widen(&dir[k][start..start + cnt], b);
            }
            renormalise(&mut bd, cnt);
            let [x, y, z] = &bd;
            core_density::<f64>(b, c, [&x[..cnt], &y[..cnt], &z[..cnt]], &mut bo[..cnt]);
            narrow(&bo[..cnt], &mut out[start..start + cnt]);
            start += cnt;
        }
        return;
    };
    let out = as_f64_mut(out).expect("T is f64");
    match backend_for(b, c) {
        // SAFETY (both): as in `core_sample`.
        #[cfg(target_arch = "x86_64")]
        Backend::Avx512 => unsafe { super::avx512::k4::density_slices(&c.view(), [x, y, z], out) },
        #[cfg(target_arch = "x86_64")]
        Backend::Avx2Fma => unsafe { super::avx2::density_slices(&c.view(), [x, y, z], out) },
        _ => portable::density_slices(&c.view(), [x, y, z], out),
    }
}

/// The inverse map of `c` at each direction (NaN handling is the caller's).
pub(crate) fn core_invert<T: Elem>(b: Backend, c: &HdsCore, dir: [&[T]; 3], out: [&mut [T]; 2]) {
    let (Some(x), Some(y), Some(z)) = (as_f64(dir[0]), as_f64(dir[1]), as_f64(dir[2])) else {
        let [u, v] = out;
        let mut bd = [[0.0; F32_CHUNK]; 3];
        let (mut bu, mut bv) = ([0.0; F32_CHUNK], [0.0; F32_CHUNK]);
        let mut start = 0;
        while start < u.len() {
            let cnt = (u.len() - start).min(F32_CHUNK);
            for (k, b) in bd.iter_mut().enumerate() {
                widen(&dir[k][start..start + cnt], b);
            }
            renormalise(&mut bd, cnt);
            let [x, y, z] = &bd;
            core_invert::<f64>(
                b,
                c,
                [&x[..cnt], &y[..cnt], &z[..cnt]],
                [&mut bu[..cnt], &mut bv[..cnt]],
            );
            narrow(&bu[..cnt], &mut u[start..start + cnt]);
            narrow(&bv[..cnt], &mut v[start..start + cnt]);
            start += cnt;
        }
        return;
    };
    let out = out.map(|o| as_f64_mut(o).expect("T is f64"));
    match backend_for(b, c) {
        // SAFETY (both): as in `core_sample`.
        #[cfg(target_arch = "x86_64")]
        Backend::Avx512 => unsafe { super::avx512::k4::invert_slices(&c.view(), [x, y, z], out) },
        #[cfg(target_arch = "x86_64")]
        Backend::Avx2Fma => unsafe { super::avx2::invert_slices(&c.view(), [x, y, z], out) },
        _ => portable::invert_slices(&c.view(), [x, y, z], out),
    }
}

// ---- Tables given as a view: the float32 map's f32 kernels and its exact f64 reference. ----

/// The forward map of the tables `t` in `E`'s kernels (f32: the float32 map; f64: the same
/// tables evaluated by the f64 kernels), on backend `b` or the fastest below it that the CPU
/// has. The caller guarantees the 32-bit index limits of the explicit kernels
/// ([`crate::mapping::Float32Map`] checks them at build).
pub(crate) fn tables_sample<E: TablesElem>(
    b: Backend,
    t: &TablesView<'_, E>,
    u: &[E],
    v: &[E],
    out: [&mut [E]; 4],
) {
    E::sample(b.usable(), t, u, v, out)
}

/// The disk density D of the tables `t` at each direction (see [`tables_sample`]).
pub(crate) fn tables_density<E: TablesElem>(
    b: Backend,
    t: &TablesView<'_, E>,
    dir: [&[E]; 3],
    out: &mut [E],
) {
    E::density(b.usable(), t, dir, out)
}

/// The inverse map of the tables `t` at each direction (see [`tables_sample`]).
pub(crate) fn tables_invert<E: TablesElem>(
    b: Backend,
    t: &TablesView<'_, E>,
    dir: [&[E]; 3],
    out: [&mut [E]; 2],
) {
    E::invert(b.usable(), t, dir, out)
}

/// An element type whose kernels run on tables given as a view: f32 (the f32 kernels) and f64
/// (the f64 kernels). `b` is a backend the CPU has.
pub(crate) trait TablesElem: Elem {
    /// The forward map.
    fn sample(b: Backend, t: &TablesView<'_, Self>, u: &[Self], v: &[Self], out: [&mut [Self]; 4]);
    /// The disk density.
    fn density(b: Backend, t: &TablesView<'_, Self>, dir: [&[Self]; 3], out: &mut [Self]);
    /// The inverse map.
    fn invert(b: Backend, t: &TablesView<'_, Self>, dir: [&[Self]; 3], out: [&mut [Self]; 2]);
}

impl TablesElem for f64 {
    fn sample(b: Backend, t: &TablesView<'_>, u: &[f64], v: &[f64], out: [&mut [f64]; 4]) {
        match b {
            // SAFETY (both): `b` is a backend the CPU has (the callers pass `Backend::usable`).
            #[cfg(target_arch = "x86_64")]
            Backend::Avx512 => unsafe { super::avx512::k2::sample_slices(t, u, v, out) },
            #[cfg(target_arch = "x86_64")]
            Backend::Avx2Fma => unsafe { super::avx2::sample_slices(t, u, v, out) },
            _ => portable::sample_slices(t, u, v, out),
        }
    }
    fn density(b: Backend, t: &TablesView<'_>, dir: [&[f64]; 3], out: &mut [f64]) {
        match b {
            // SAFETY (both): as in `sample`.
            #[cfg(target_arch = "x86_64")]
            Backend::Avx512 => unsafe { super::avx512::k4::density_slices(t, dir, out) },
            #[cfg(target_arch = "x86_64")]
            Backend::Avx2Fma => unsafe { super::avx2::density_slices(t, dir, out) },
            _ => portable::density_slices(t, dir, out),
        }
    }
    fn invert(b: Backend, t: &TablesView<'_>, dir: [&[f64]; 3], out: [&mut [f64]; 2]) {
        match b {
            // SAFETY (both): as in `sample`.
            #[cfg(target_arch = "x86_64")]
            Backend::Avx512 => unsafe { super::avx512::k4::invert_slices(t, dir, out) },
            #[cfg(target_arch = "x86_64")]
            Backend::Avx2Fma => unsafe { super::avx2::invert_slices(t, dir, out) },
            _ => portable::invert_slices(t, dir, out),
        }
    }
}

impl TablesElem for f32 {
    fn sample(b: Backend, t: &TablesView<'_, f32>, u: &[f32], v: &[f32], out: [&mut [f32]; 4]) {
        match b {
            // SAFETY (both): as in the f64 `sample`.
            #[cfg(target_arch = "x86_64")]
            Backend::Avx512 => unsafe { super::avx512::f32_k4::sample_slices(t, u, v, out) },
            #[cfg(target_arch = "x86_64")]
            Backend::Avx2Fma => unsafe { super::avx2::f32_k2::sample_slices(t, u, v, out) },
            _ => super::portable::f32_lanes::sample_slices(t, u, v, out),
        }
    }
    fn density(b: Backend, t: &TablesView<'_, f32>, dir: [&[f32]; 3], out: &mut [f32]) {
        match b {
            // SAFETY (both): as in the f64 `sample`.
            #[cfg(target_arch = "x86_64")]
            Backend::Avx512 => unsafe { super::avx512::f32_k4::density_slices(t, dir, out) },
            #[cfg(target_arch = "x86_64")]
            Backend::Avx2Fma => unsafe { super::avx2::f32_k2::density_slices(t, dir, out) },
            _ => super::portable::f32_lanes::density_slices(t, dir, out),
        }
    }
    fn invert(b: Backend, t: &TablesView<'_, f32>, dir: [&[f32]; 3], out: [&mut [f32]; 2]) {
        match b {
            // SAFETY (both): as in the f64 `sample`.
            #[cfg(target_arch = "x86_64")]
            Backend::Avx512 => unsafe { super::avx512::f32_k4::invert_slices(t, dir, out) },
            #[cfg(target_arch = "x86_64")]
            Backend::Avx2Fma => unsafe { super::avx2::f32_k2::invert_slices(t, dir, out) },
            _ => super::portable::f32_lanes::invert_slices(t, dir, out),
        }
    }
}

/// Polar angle θ (to `out[0]`) and azimuth φ (to `out[1]`) of unit directions on backend `b` (the
/// fastest below it if the CPU lacks it): [`super::math::angles`] per direction, bit for bit, on
/// every backend.
pub(crate) fn angles(b: Backend, dir: [&[f64]; 3], out: [&mut [f64]; 2]) {
    match b.usable() {
        // SAFETY (both): `usable` returns a backend only when the CPU has its instruction set.
        #[cfg(target_arch = "x86_64")]
        Backend::Avx512 => unsafe { super::avx512::k4::angles_slices(dir, out) },
        #[cfg(target_arch = "x86_64")]
        Backend::Avx2Fma => unsafe { super::avx2::angles_slices(dir, out) },
        _ => portable::angles_slices(dir, out),
    }
}
