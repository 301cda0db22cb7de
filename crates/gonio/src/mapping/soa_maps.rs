//! The [`SoaSampler`] impls of the two HDS maps: [`HemisphereMap`] runs its one table set through
//! the batch kernels; [`SphereMap`] runs its layout's maps, the split layout partitioning the
//! points by hemisphere. Kept apart from [`super::batch`] (the trait, the kernel dispatch, the
//! parallel and AoS adapters), which knows no map type, so that the maps can call the batch
//! adapters without an import circle.

// Lane loops index several arrays by the same lane number on purpose (they vectorise).
#![allow(clippy::needless_range_loop)]

use super::batch::{check_len, core_density, core_invert, core_sample, SoaSampler, CHUNK};
use super::simd::{Backend, BatchFloat, Elem};
use super::sphere::CoresRef;
use super::split::{Side, SplitRule};
use super::{HemisphereMap, SphereMap};

impl SoaSampler for HemisphereMap {
    fn sample_soa_with<T: BatchFloat>(
        &self,
        backend: Backend,
        u: &[T],
        v: &[T],
        dir: [&mut [T]; 3],
        pdf: &mut [T],
    ) {
        let [x, y, z] = dir;
        check_len(
            "sample_soa",
            u.len(),
            &[v.len(), x.len(), y.len(), z.len(), pdf.len()],
        );
        core_sample(backend, self.core(), u, v, [x, y, z, &mut *pdf]);
        let s = T::from_f64(self.inv_2t());
        for p in pdf.iter_mut() {
            *p = *p * s;
        }
    }
    fn pdf_soa_with<T: BatchFloat>(&self, backend: Backend, dir: [&[T]; 3], pdf: &mut [T]) {
        check_len(
            "pdf_soa",
            pdf.len(),
            &[dir[0].len(), dir[1].len(), dir[2].len()],
        );
        core_density(backend, self.core(), dir, pdf);
        let s = T::from_f64(self.inv_2t());
        for (p, &z) in pdf.iter_mut().zip(dir[2]) {
            *p = if z >= T::ZERO { *p * s } else { T::ZERO };
        }
    }
    fn invert_soa_with<T: BatchFloat>(&self, backend: Backend, dir: [&[T]; 3], uv: [&mut [T]; 2]) {
        let [u, v] = uv;
        check_len(
            "invert_soa",
            u.len(),
            &[v.len(), dir[0].len(), dir[1].len(), dir[2].len()],
        );
        core_invert(backend, self.core(), dir, [&mut *u, &mut *v]);
        // No preimage below the horizon or for a non-finite direction. Evaluated without
        // short-circuits or indexing, so that the pass compiles to selects.
        for (((u, v), x), (y, z)) in u
            .iter_mut()
            .zip(v.iter_mut())
            .zip(dir[0])
            .zip(dir[1].iter().zip(dir[2]))
        {
            let ok = (*z >= T::ZERO) & x.is_finite() & y.is_finite() & z.is_finite();
            if !ok {
                *u = T::NAN;
                *v = T::NAN;
            }
        }
    }
}

impl SoaSampler for SphereMap {
    fn sample_soa_with<T: BatchFloat>(
        &self,
        backend: Backend,
        u: &[T],
        v: &[T],
        dir: [&mut [T]; 3],
        pdf: &mut [T],
    ) {
        let [x, y, z] = dir;
        check_len(
            "sample_soa",
            u.len(),
            &[v.len(), x.len(), y.len(), z.len(), pdf.len()],
        );
        let s = T::from_f64(self.inv_2t());
        match self.cores() {
            CoresRef::Lambert(c) => core_sample(backend, c, u, v, [x, y, z, &mut *pdf]),
            CoresRef::Split {
                upper: Some(c),
                lower: None,
                ..
            } => core_sample(backend, c, u, v, [x, y, z, &mut *pdf]),
            CoresRef::Split {
                upper: None,
                lower: Some(c),
                ..
            } => {
                core_sample(backend, c, u, v, [x, y, &mut *z, &mut *pdf]);
                for z in z.iter_mut() {
                    *z = -*z;
                }
            }
            CoresRef::Split {
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
                        core_sample(
                            backend,
                            core,
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
            CoresRef::Split {
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
            *p = *p * s;
        }
    }

    fn pdf_soa_with<T: BatchFloat>(&self, backend: Backend, dir: [&[T]; 3], pdf: &mut [T]) {
        check_len(
            "pdf_soa",
            pdf.len(),
            &[dir[0].len(), dir[1].len(), dir[2].len()],
        );
        let s = T::from_f64(self.inv_2t());
        match self.cores() {
            CoresRef::Lambert(c) => core_density(backend, c, dir, pdf),
            CoresRef::Split { upper, lower, rule } => {
                split_by_side(dir, rule, |side, d, pos| {
                    let core = CoresRef::side(upper, lower, side);
                    let mut o = [T::ZERO; CHUNK];
                    let o = &mut o[..pos.len()];
                    match core {
                        Some(c) => core_density(backend, c, d, o),
                        None => o.fill(T::ZERO),
                    }
                    for (q, &k) in pos.iter().enumerate() {
                        pdf[k] = o[q];
                    }
                });
            }
        }
        for p in pdf.iter_mut() {
            *p = *p * s;
        }
    }

    fn invert_soa_with<T: BatchFloat>(&self, backend: Backend, dir: [&[T]; 3], uv: [&mut [T]; 2]) {
        let [u, v] = uv;
        check_len(
            "invert_soa",
            u.len(),
            &[v.len(), dir[0].len(), dir[1].len(), dir[2].len()],
        );
        match self.cores() {
            CoresRef::Lambert(c) => core_invert(backend, c, dir, [&mut *u, &mut *v]),
            CoresRef::Split { upper, lower, rule } => {
                split_by_side(dir, rule, |side, d, pos| {
                    let core = CoresRef::side(upper, lower, side);
                    let (mut ou, mut ov) = ([T::ZERO; CHUNK], [T::ZERO; CHUNK]);
                    let (ou, ov) = (&mut ou[..pos.len()], &mut ov[..pos.len()]);
                    match core {
                        Some(c) => core_invert(backend, c, d, [&mut *ou, &mut *ov]),
                        None => {
                            ou.fill(T::NAN);
                            ov.fill(T::NAN);
                        }
                    }
                    for (q, &k) in pos.iter().enumerate() {
                        // No preimage stays NaN (`min` below would turn NaN into 1).
                        u[k] = if !ou[q].is_finite() {
                            T::NAN
                        } else {
                            // As the scalar inverse, in the element type's precision.
                            rule.join_u(side, ou[q])
                        };
                        v[k] = ov[q];
                    }
                });
            }
        }
        for (((u, v), x), (y, z)) in u
            .iter_mut()
            .zip(v.iter_mut())
            .zip(dir[0])
            .zip(dir[1].iter().zip(dir[2]))
        {
            if !(x.is_finite() & y.is_finite() & z.is_finite()) {
                *u = T::NAN;
                *v = T::NAN;
            }
        }
    }
}

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
