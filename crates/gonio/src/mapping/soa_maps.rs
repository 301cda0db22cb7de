//! The one layout driver of every HDS map's batch calls (issue 36): a map is a [`Shape`] (one
//! hemisphere map, the Lambert sphere, or the split sphere's upper and/or lower map and the rule
//! between them) over the kernels of its hemisphere maps ([`Kernel`]); the split layout partitions
//! the points by hemisphere here, once. Two kinds of kernels run under it: an f64 map's own tables
//! ([`CoreKernel`], any element type: f32 calls widened to the f64 kernels and rounded once) and a
//! table view in its own element type ([`ViewKernel`]: the float32 map's f32 tables, the f64 tables
//! read back from a blob, the float32 map evaluated exactly). [`HemisphereMap`] and [`SphereMap`]
//! implement [`SoaSampler`] with it; `float32.rs`'s maps call it. Kept apart from
//! [`super::batch`] (the trait, the kernel dispatch, the parallel adapters), which knows no map
//! type, so that the maps can call the batch adapters without an import circle.

// Lane loops index several arrays by the same lane number on purpose (they vectorise).
#![allow(clippy::needless_range_loop)]

use super::batch::{check_len, core_density, core_invert, core_sample, SoaSampler, CHUNK};
use super::hds::{HdsCore, TablesView};
use super::simd::dispatch::{tables_density, tables_invert, tables_sample, TablesElem};
use super::simd::{Backend, BatchFloat, Elem};
use super::sphere::CoresRef;
use super::split::{Side, SplitRule};
use super::{HemisphereMap, SphereMap};

/// The kernels of one hemisphere map on slices of `T`: the forward map (directions and the disk
/// density D to `out`), the disk density, the inverse (NaN where there is no preimage).
pub(super) trait Kernel<T> {
    /// The forward map: directions to `out[0..3]`, the disk density D to `out[3]`.
    fn sample(&self, u: &[T], v: &[T], out: [&mut [T]; 4]);
    /// The disk density D at each direction of the map's hemisphere (z ≥ 0).
    fn density(&self, dir: [&[T]; 3], out: &mut [T]);
    /// The point of the map's square of each direction.
    fn invert(&self, dir: [&[T]; 3], out: [&mut [T]; 2]);
}

/// An f64 map's own tables on a backend ([`core_sample`], [`core_density`], [`core_invert`]:
/// f32 slices are widened to the f64 kernels and rounded once; a map too large for the explicit
/// kernels' 32-bit index conversions runs the portable ones).
#[derive(Clone, Copy)]
pub(super) struct CoreKernel<'a> {
    pub(super) backend: Backend,
    pub(super) core: &'a HdsCore,
}

impl<T: Elem> Kernel<T> for CoreKernel<'_> {
    #[inline]
    fn sample(&self, u: &[T], v: &[T], out: [&mut [T]; 4]) {
        core_sample(self.backend, self.core, u, v, out)
    }
    #[inline]
    fn density(&self, dir: [&[T]; 3], out: &mut [T]) {
        core_density(self.backend, self.core, dir, out)
    }
    #[inline]
    fn invert(&self, dir: [&[T]; 3], out: [&mut [T]; 2]) {
        core_invert(self.backend, self.core, dir, out)
    }
}

/// Tables given as a view, in their own element type, on a backend.
#[derive(Clone, Copy)]
pub(super) struct ViewKernel<'a, E> {
    pub(super) backend: Backend,
    pub(super) tables: TablesView<'a, E>,
}

impl<E: TablesElem> Kernel<E> for ViewKernel<'_, E> {
    #[inline]
    fn sample(&self, u: &[E], v: &[E], out: [&mut [E]; 4]) {
        tables_sample(self.backend, &self.tables, u, v, out)
    }
    #[inline]
    fn density(&self, dir: [&[E]; 3], out: &mut [E]) {
        tables_density(self.backend, &self.tables, dir, out)
    }
    #[inline]
    fn invert(&self, dir: [&[E]; 3], out: [&mut [E]; 2]) {
        tables_invert(self.backend, &self.tables, dir, out)
    }
}

/// A map's layout over the kernels of its hemisphere maps.
pub(super) enum Shape<K> {
    /// One map of the upper hemisphere (z ≥ 0).
    Hemisphere(K),
    /// The Lambert sphere: one map over the whole sphere.
    Lambert(K),
    /// The split sphere: an upper and/or a lower map (the lower one mirrored to z ≥ 0) and the
    /// rule between them.
    Split {
        upper: Option<K>,
        lower: Option<K>,
        rule: SplitRule,
    },
}

impl<K> Shape<K> {
    /// Maps the points `(u[k], v[k])` to directions and densities: the kernels' disk densities
    /// times `inv_2t` = 1/(2T).
    pub(super) fn sample<T: Elem>(
        &self,
        inv_2t: T,
        u: &[T],
        v: &[T],
        dir: [&mut [T]; 3],
        pdf: &mut [T],
    ) where
        K: Kernel<T>,
    {
        let [x, y, z] = dir;
        check_len(
            "sample_soa",
            u.len(),
            &[v.len(), x.len(), y.len(), z.len(), pdf.len()],
        );
        match self {
            Shape::Hemisphere(c)
            | Shape::Lambert(c)
            | Shape::Split {
                upper: Some(c),
                lower: None,
                ..
            } => c.sample(u, v, [x, y, z, &mut *pdf]),
            Shape::Split {
                upper: None,
                lower: Some(c),
                ..
            } => {
                c.sample(u, v, [x, y, &mut *z, &mut *pdf]);
                for z in z.iter_mut() {
                    *z = -*z;
                }
            }
            Shape::Split {
                upper: Some(up),
                lower: Some(lo),
                rule,
            } => {
                let mut start = 0;
                while start < u.len() {
                    let cnt = (u.len() - start).min(CHUNK);
                    // Partition the chunk by hemisphere, with the square rescaled as in the scalar
                    // `SphereMap::sample`.
                    let mut idx = [[0u16; CHUNK]; 2];
                    let mut nn = [0usize; 2];
                    let mut bu = [[T::ZERO; CHUNK]; 2];
                    let mut bv = [[T::ZERO; CHUNK]; 2];
                    for k in 0..cnt {
                        let (uu, vv) = (u[start + k], v[start + k]);
                        let (side, w) = rule.split_u(uu);
                        let side = side as usize;
                        let at = nn[side];
                        idx[side][at] = k as u16;
                        bu[side][at] = w;
                        bv[side][at] = vv;
                        nn[side] += 1;
                    }
                    for (side, core) in [(0usize, lo), (1, up)] {
                        let cn = nn[side];
                        if cn == 0 {
                            continue;
                        }
                        let mut o = [[T::ZERO; CHUNK]; 4];
                        let [ox, oy, oz, od] = &mut o;
                        core.sample(
                            &bu[side][..cn],
                            &bv[side][..cn],
                            [&mut ox[..cn], &mut oy[..cn], &mut oz[..cn], &mut od[..cn]],
                        );
                        for q in 0..cn {
                            let k = start + idx[side][q] as usize;
                            x[k] = ox[q];
                            y[k] = oy[q];
                            z[k] = if side == 0 { -oz[q] } else { oz[q] };
                            pdf[k] = od[q];
                        }
                    }
                    start += cnt;
                }
            }
            Shape::Split {
                upper: None,
                lower: None,
                ..
            } => {
                // Refused at build time (zero power); as the scalar path.
                x.fill(T::ZERO);
                y.fill(T::ZERO);
                z.fill(T::ONE);
                pdf.fill(T::ZERO);
            }
        }
        for p in pdf.iter_mut() {
            *p = *p * inv_2t;
        }
    }

    /// The density (per steradian) at each direction: the kernels' disk density times `inv_2t`;
    /// 0 below the horizon of a hemisphere map and on a side without a map.
    pub(super) fn pdf<T: Elem>(&self, inv_2t: T, dir: [&[T]; 3], pdf: &mut [T])
    where
        K: Kernel<T>,
    {
        check_len(
            "pdf_soa",
            pdf.len(),
            &[dir[0].len(), dir[1].len(), dir[2].len()],
        );
        match self {
            Shape::Hemisphere(c) => {
                c.density(dir, pdf);
                for (p, &z) in pdf.iter_mut().zip(dir[2]) {
                    *p = if z >= T::ZERO { *p * inv_2t } else { T::ZERO };
                }
                return;
            }
            Shape::Lambert(c) => c.density(dir, pdf),
            Shape::Split { upper, lower, rule } => {
                split_by_side(dir, *rule, |side, d, pos| {
                    let core = match side {
                        Side::Lower => lower,
                        Side::Upper => upper,
                    };
                    let mut o = [T::ZERO; CHUNK];
                    let o = &mut o[..pos.len()];
                    if let Some(c) = core {
                        c.density(d, o);
                    }
                    for (q, &k) in pos.iter().enumerate() {
                        pdf[k] = o[q];
                    }
                });
            }
        }
        for p in pdf.iter_mut() {
            *p = *p * inv_2t;
        }
    }

    /// The point of the square of each direction; NaN where there is no preimage (a side without
    /// a map, below the horizon of a hemisphere map, a non-finite direction).
    pub(super) fn invert<T: Elem>(&self, dir: [&[T]; 3], uv: [&mut [T]; 2])
    where
        K: Kernel<T>,
    {
        let [u, v] = uv;
        check_len(
            "invert_soa",
            u.len(),
            &[v.len(), dir[0].len(), dir[1].len(), dir[2].len()],
        );
        let hemisphere = matches!(self, Shape::Hemisphere(_));
        match self {
            Shape::Hemisphere(c) | Shape::Lambert(c) => c.invert(dir, [&mut *u, &mut *v]),
            Shape::Split { upper, lower, rule } => {
                split_by_side(dir, *rule, |side, d, pos| {
                    let core = match side {
                        Side::Lower => lower,
                        Side::Upper => upper,
                    };
                    let (mut ou, mut ov) = ([T::NAN; CHUNK], [T::NAN; CHUNK]);
                    let (ou, ov) = (&mut ou[..pos.len()], &mut ov[..pos.len()]);
                    if let Some(c) = core {
                        c.invert(d, [&mut *ou, &mut *ov]);
                    }
                    for (q, &k) in pos.iter().enumerate() {
                        // No preimage stays NaN (`min` in `join_u` would turn NaN into 1).
                        u[k] = if ou[q].is_finite() {
                            rule.join_u(side, ou[q])
                        } else {
                            T::NAN
                        };
                        v[k] = ov[q];
                    }
                });
            }
        }
        // No preimage below the horizon of a hemisphere map or for a non-finite direction.
        if hemisphere {
            no_preimage::<T, true>(dir, [u, v]);
        } else {
            no_preimage::<T, false>(dir, [u, v]);
        }
    }
}

/// NaN in both coordinates of `uv` where the direction is not finite, or (`HEMISPHERE`) below the
/// horizon. Evaluated without short-circuits or indexing, one loop per layout, so that the pass
/// compiles to selects.
#[inline(always)]
fn no_preimage<T: Elem, const HEMISPHERE: bool>(dir: [&[T]; 3], uv: [&mut [T]; 2]) {
    let [u, v] = uv;
    for (((u, v), x), (y, z)) in u
        .iter_mut()
        .zip(v.iter_mut())
        .zip(dir[0])
        .zip(dir[1].iter().zip(dir[2]))
    {
        let ok = if HEMISPHERE {
            (*z >= T::ZERO) & x.is_finite() & y.is_finite() & z.is_finite()
        } else {
            x.is_finite() & y.is_finite() & z.is_finite()
        };
        if !ok {
            *u = T::NAN;
            *v = T::NAN;
        }
    }
}

impl HemisphereMap {
    /// The map as a [`Shape`] over its own tables on `backend`.
    fn shape(&self, backend: Backend) -> Shape<CoreKernel<'_>> {
        Shape::Hemisphere(CoreKernel {
            backend,
            core: self.core(),
        })
    }
}

impl SphereMap {
    /// The map as a [`Shape`] over its own tables on `backend`.
    fn shape(&self, backend: Backend) -> Shape<CoreKernel<'_>> {
        let k = |core| CoreKernel { backend, core };
        match self.cores() {
            CoresRef::Lambert(c) => Shape::Lambert(k(c)),
            CoresRef::Split { upper, lower, rule } => Shape::Split {
                upper: upper.map(k),
                lower: lower.map(k),
                rule,
            },
        }
    }
}

/// The [`SoaSampler`] of an HDS map: its [`Shape`] over its own tables.
macro_rules! soa_sampler {
    ($map:ty) => {
        impl SoaSampler for $map {
            fn sample_soa_with<T: BatchFloat>(
                &self,
                backend: Backend,
                u: &[T],
                v: &[T],
                dir: [&mut [T]; 3],
                pdf: &mut [T],
            ) {
                self.shape(backend)
                    .sample(T::from_f64(self.inv_2t()), u, v, dir, pdf)
            }
            fn pdf_soa_with<T: BatchFloat>(&self, backend: Backend, dir: [&[T]; 3], pdf: &mut [T]) {
                self.shape(backend)
                    .pdf(T::from_f64(self.inv_2t()), dir, pdf)
            }
            fn invert_soa_with<T: BatchFloat>(
                &self,
                backend: Backend,
                dir: [&[T]; 3],
                uv: [&mut [T]; 2],
            ) {
                self.shape(backend).invert(dir, uv)
            }
        }
    };
}
soa_sampler!(HemisphereMap);
soa_sampler!(SphereMap);

/// Splits directions into chunks and each chunk by hemisphere ([`SplitRule::side_of`]); calls
/// `f(side, dirs, positions)` with the lower side's directions mirrored to z ≥ 0.
pub(super) fn split_by_side<T: Elem>(
    dir: [&[T]; 3],
    rule: SplitRule,
    mut f: impl FnMut(Side, [&[T]; 3], &[usize]),
) {
    let len = dir[0].len();
    let mut start = 0;
    while start < len {
        let cnt = (len - start).min(CHUNK);
        let mut pos = [[0usize; CHUNK]; 2];
        let mut b = [[[T::ZERO; CHUNK]; 3]; 2];
        let mut nn = [0usize; 2];
        for k in start..start + cnt {
            let z = dir[2][k];
            let side = rule.side_of(z) as usize;
            let at = nn[side];
            pos[side][at] = k;
            b[side][0][at] = dir[0][k];
            b[side][1][at] = dir[1][k];
            b[side][2][at] = if side == 0 { -z } else { z };
            nn[side] += 1;
        }
        for (side, which) in [(0, Side::Lower), (1, Side::Upper)] {
            let cn = nn[side];
            if cn > 0 {
                let d = [&b[side][0][..cn], &b[side][1][..cn], &b[side][2][..cn]];
                f(which, d, &pos[side][..cn]);
            }
        }
        start += cnt;
    }
}
