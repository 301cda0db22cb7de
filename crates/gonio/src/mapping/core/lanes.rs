//! The batch (structure-of-arrays) kernels of one HDS map: [`HdsCore::sample`], `density` and
//! `invert` over blocks of [`LANES`] points (see [`crate::mapping::simd`] for how they are written).
//!
//! In f64 every arithmetic step is the scalar path's, in its order (so the results are the scalar
//! ones bit for bit except through sin/cos and atan2); in f32 the same steps run in f32 with the
//! tables read from their f64 values, while the table searches compare in f64 (exact for f32
//! inputs). The batch paths run only the f64 instantiation (f32 calls are widened to f64 in
//! `mapping::batch`); the f32 one stays generic, unused by them.

// Lane loops index several arrays by the same lane number on purpose (they vectorise).
#![allow(clippy::needless_range_loop)]

use super::HdsCore;
use crate::mapping::simd::{Lane, LANES as L};
use std::f64::consts::{FRAC_PI_2, FRAC_PI_4, PI, TAU};

/// Points of the square that pad a partial block (any valid point).
const PAD: f64 = 0.5;

#[inline(always)]
fn c<T: Lane>(x: f64) -> T {
    T::from_f64(x)
}

/// `radial::partial_mass` in the lane type, same operation order.
#[inline(always)]
fn partial_mass<T: Lane>(x0: T, d0: T, k: T, tau: T) -> T {
    tau * (c::<T>(2.0) * x0 * d0 + tau * ((x0 * k + d0) + tau * c::<T>(2.0 / 3.0) * k))
}

/// `lift::sphere_to_disk_radius` and the azimuth of `core::azimuth`, per lane.
#[inline(always)]
fn radius_azimuth<T: Lane>(x: &[T; L], y: &[T; L], z: &[T; L]) -> ([T; L], [T; L]) {
    let mut xr = [T::ZERO; L];
    let mut p = [T::ZERO; L];
    for l in 0..L {
        let r2 = if z[l] > T::ZERO {
            (x[l] * x[l] + y[l] * y[l]) / (T::ONE + z[l])
        } else {
            T::ONE - z[l]
        };
        xr[l] = r2.clamp(T::ZERO, T::TWO).sqrt();
    }
    for l in 0..L {
        let mut phi = y[l].atan2(x[l]);
        phi = if phi < T::ZERO { phi + c(TAU) } else { phi };
        phi = if phi >= c(TAU) { T::ZERO } else { phi };
        // The poles read meridian 0 (φ = 0), whatever the signs of the zeros.
        let pole = x[l] == T::ZERO && y[l] == T::ZERO;
        p[l] = if pole { T::ZERO } else { phi };
    }
    (xr, p)
}

impl HdsCore {
    /// Sector index of azimuth `p` (as `HdsCore::sector`, without ε).
    #[inline(always)]
    fn sector_index(&self, p: f64) -> usize {
        if self.angular.inv_uniform_beta > 0.0 {
            let (phi, m) = (&self.angular.phi, self.angular.m);
            let i = ((p * self.angular.inv_uniform_beta) as usize).min(m - 1);
            // Round-off of the product: one step either way, as selects (no branch to mispredict).
            let down = p < phi[i];
            let up = !down && i + 1 < m && p >= phi[i + 1];
            i - usize::from(down) + usize::from(up)
        } else {
            crate::diagram::segment(&self.angular.phi, p)
        }
    }

    /// The wedge of each B-disk azimuth of a block (`Angular::wedge`: the largest i ≤ M − 1 with
    /// Γ_i ≤ φ_B).
    #[inline(always)]
    fn wedges<T: Lane>(&self, pb: &[T; L], out: &mut [usize; L]) {
        let a = &self.angular;
        *out = guided_block(&a.cum, &a.wedge_guide, a.guide_scale, pb, a.m - 1);
    }

    /// The parallel segment of each disk radius of a block (`Radial::segment_of`: the largest
    /// j ≤ N − 2 with x_j ≤ x_r).
    #[inline(always)]
    fn segments_of<T: Lane>(&self, xr: &[T; L]) -> [usize; L] {
        let r = &self.radial;
        guided_block(&r.x, &r.radius_guide, r.radius_scale, xr, r.n - 2)
    }

    /// Sector, ε and the next meridian for a block of azimuths (`HdsCore::sector`).
    #[inline(always)]
    fn sectors<T: Lane>(&self, p: &[T; L]) -> ([usize; L], [usize; L], [T; L]) {
        let mut i = [0usize; L];
        let mut i1 = [0usize; L];
        let mut phi0 = [T::ZERO; L];
        let mut beta = [T::ONE; L];
        for l in 0..L {
            let s = self.sector_index(p[l].to_f64());
            i[l] = s;
            i1[l] = self.angular.next(s);
            phi0[l] = c(self.angular.phi[s]);
            beta[l] = c(self.angular.beta[s]);
        }
        let mut eps = [T::ZERO; L];
        for l in 0..L {
            eps[l] = ((p[l] - phi0[l]) / beta[l]).clamp(T::ZERO, T::ONE);
        }
        (i, i1, eps)
    }

    /// The forward map on one block: directions and the disk density D at each sample.
    #[inline(always)]
    pub(crate) fn sample_block<T: Lane>(&self, u: &[T; L], v: &[T; L], out: [&mut [T; L]; 4]) {
        let n = self.radial.n;
        // M_B (concentric::square_to_disk), branch-free.
        let mut rb = [T::ZERO; L];
        let mut pb = [T::ZERO; L];
        for l in 0..L {
            let a = T::TWO * u[l] - T::ONE;
            let b = T::TWO * v[l] - T::ONE;
            let big = a.abs() > b.abs();
            let (r, num, den) = if big { (a, b, a) } else { (b, a, b) };
            let q = num / den;
            let phi = if big {
                c::<T>(FRAC_PI_4) * q
            } else {
                c::<T>(FRAC_PI_2) - c::<T>(FRAC_PI_4) * q
            };
            let neg = r < T::ZERO;
            let r = if neg { -r } else { r };
            let phi = if neg { phi + c(PI) } else { phi };
            let phi = if phi < T::ZERO { phi + c(TAU) } else { phi };
            let phi = if phi >= c(TAU) { T::ZERO } else { phi };
            let zero = a == T::ZERO && b == T::ZERO;
            rb[l] = if zero { T::ZERO } else { r };
            pb[l] = if zero { T::ZERO } else { phi };
        }
        // M_C: wedge search per lane, then the wedge equation (angular::solve_wedge) in lanes.
        let mut wi = [0usize; L];
        let (mut beta, mut ra, mut rbb, mut cum, mut phi0) = (
            [T::ZERO; L],
            [T::ZERO; L],
            [T::ZERO; L],
            [T::ZERO; L],
            [T::ZERO; L],
        );
        self.wedges(&pb, &mut wi);
        for l in 0..L {
            let i = wi[l];
            beta[l] = c(self.angular.beta[i]);
            ra[l] = c(self.angular.r2[i]);
            rbb[l] = c(self.angular.r2[i + 1]);
            cum[l] = c(self.angular.cum[i]);
            phi0[l] = c(self.angular.phi[i]);
        }
        let kappa: T = c(self.angular.kappa);
        let mut eps = [T::ZERO; L];
        let mut phic = [T::ZERO; L];
        for l in 0..L {
            let gamma = (pb[l] - cum[l]) / kappa;
            let a = T::HALF * beta[l] * (rbb[l] - ra[l]);
            let b = beta[l] * ra[l];
            let cc = gamma.max(T::ZERO);
            let den = b + (b * b + c::<T>(4.0) * a * cc).max(T::ZERO).sqrt();
            let e = if den > T::ZERO {
                (T::TWO * cc / den).clamp(T::ZERO, T::ONE)
            } else {
                T::ZERO
            };
            eps[l] = e;
            phic[l] = phi0[l] + e * beta[l];
        }
        // M_D: the radial search per lane (as HdsCore::sample), gathers for the solve.
        let kg = self.radial.radial_k;
        let (mut x0, mut x1, mut inv_dx, mut d0, mut d1, mut m) = (
            [T::ZERO; L],
            [T::ZERO; L],
            [T::ZERO; L],
            [T::ZERO; L],
            [T::ZERO; L],
            [T::ZERO; L],
        );
        // The bracket of each lane's radial search from the guide tables, then one branch-free
        // descent over the whole block (`descend`).
        let (mut ra_off, mut rb_off) = ([0usize; L], [0usize; L]);
        let (mut lo, mut hi, mut w) = ([0usize; L], [0usize; L], [T::ZERO; L]);
        let ru = &self.radial.u;
        let rg = &self.radial.radial_guide;
        for l in 0..L {
            let (a, b) = (wi[l] * n, self.angular.next(wi[l]) * n);
            ra_off[l] = a;
            rb_off[l] = b;
            let e = eps[l];
            let r2b = rb[l] * rb[l];
            let rt = &self.radial.total;
            let (ta, tb) = (rt[wi[l]], rt[self.angular.next(wi[l])]);
            w[l] = r2b * ((T::ONE - e) * c::<T>(ta) + e * c::<T>(tb));
            let k = (r2b * c::<T>(kg as f64)).to_usize().min(kg - 1);
            let (ga, gb) = (
                wi[l] * (kg + 1) + k,
                self.angular.next(wi[l]) * (kg + 1) + k,
            );
            lo[l] = rg[ga].min(rg[gb]) as usize;
            hi[l] = rg[ga + 1].max(rg[gb + 1]) as usize;
        }
        let found = descend(&lo, &hi, &w, |l, j| {
            (T::ONE - eps[l]) * c::<T>(ru[ra_off[l] + j]) + eps[l] * c::<T>(ru[rb_off[l] + j])
        });
        for l in 0..L {
            let (i, i1) = (wi[l], self.angular.next(wi[l]));
            let e = eps[l];
            let (ua, ub) = (
                &self.radial.u[i * n..i * n + n],
                &self.radial.u[i1 * n..i1 * n + n],
            );
            let ut = |j: usize| (T::ONE - e) * c::<T>(ua[j]) + e * c::<T>(ub[j]);
            let w = w[l];
            let (j, uj) = settle_radial(found[l], n, w, ut);
            let (da, db) = (
                &self.radial.d[i * n..i * n + n],
                &self.radial.d[i1 * n..i1 * n + n],
            );
            d0[l] = (T::ONE - e) * c::<T>(da[j]) + e * c::<T>(db[j]);
            d1[l] = (T::ONE - e) * c::<T>(da[j + 1]) + e * c::<T>(db[j + 1]);
            x0[l] = c(self.radial.x[j]);
            x1[l] = c(self.radial.x[j + 1]);
            inv_dx[l] = c(self.radial.inv_dx[j]);
            m[l] = w - uj;
        }
        let xr = solve_radius_block(&x0, &x1, &d0, &d1, &m);
        // Density at the radius and M_E (lift::disk_to_sphere).
        let [ox, oy, oz, od] = out;
        let north = c::<T>(self.radial.d[0]).max(T::ZERO);
        let south = c::<T>(self.radial.d[n - 1]).max(T::ZERO);
        for l in 0..L {
            let xr = xr[l].min(x1[l]);
            let r2 = xr * xr;
            let s = xr * (T::TWO - r2).max(T::ZERO).sqrt();
            let (sp, cp) = phic[l].sin_cos();
            ox[l] = s * cp;
            oy[l] = s * sp;
            oz[l] = T::ONE - r2;
            // The density at the radius the returned direction has (lift::sphere_to_disk_radius,
            // what `density_block` reads), as the scalar `HdsCore::sample`.
            let rd2 = if oz[l] > T::ZERO {
                (ox[l] * ox[l] + oy[l] * oy[l]) / (T::ONE + oz[l])
            } else {
                T::ONE - oz[l]
            };
            let xd = rd2.max(T::ZERO).min(T::TWO).sqrt();
            let t = ((xd - x0[l]) * inv_dx[l]).max(T::ZERO).min(T::ONE);
            od[l] = (d0[l] + (d1[l] - d0[l]) * t).max(T::ZERO);
            // A pole: `density` reads meridian 0 there (φ = 0): parallel 0 at the north pole,
            // the last parallel at the south pole (the rim of the Lambert disk).
            let pole_d = if oz[l] > T::ZERO { north } else { south };
            let pole = ox[l] == T::ZERO && oy[l] == T::ZERO;
            od[l] = if pole { pole_d } else { od[l] };
        }
    }

    /// The disk density D at a block of directions (`HdsCore::density`).
    #[inline(always)]
    pub(crate) fn density_block<T: Lane>(
        &self,
        x: &[T; L],
        y: &[T; L],
        z: &[T; L],
        out: &mut [T; L],
    ) {
        let n = self.radial.n;
        let (xr, p) = radius_azimuth(x, y, z);
        let (i, i1, eps) = self.sectors(&p);
        let seg = self.segments_of(&xr);
        let (mut t, mut a0, mut a1, mut b0, mut b1) = (
            [T::ZERO; L],
            [T::ZERO; L],
            [T::ZERO; L],
            [T::ZERO; L],
            [T::ZERO; L],
        );
        for l in 0..L {
            let j = seg[l];
            let (xj, idx) = (c::<T>(self.radial.x[j]), c::<T>(self.radial.inv_dx[j]));
            t[l] = ((xr[l] - xj) * idx).clamp(T::ZERO, T::ONE);
            // Two-element windows: one bounds check per pair of nodes.
            let da = &self.radial.d[i[l] * n + j..][..2];
            let db = &self.radial.d[i1[l] * n + j..][..2];
            a0[l] = c(da[0]);
            a1[l] = c(da[1]);
            b0[l] = c(db[0]);
            b1[l] = c(db[1]);
        }
        let edge = self.radial.x[n - 1] * (1.0 + 1e-12);
        for l in 0..L {
            let ra = a0[l] + t[l] * (a1[l] - a0[l]);
            let rb = b0[l] + t[l] * (b1[l] - b0[l]);
            let d = ((T::ONE - eps[l]) * ra + eps[l] * rb).max(T::ZERO);
            // Beyond the zone the map covers: no light (`HdsCore::density`).
            out[l] = if xr[l].to_f64() > edge { T::ZERO } else { d };
        }
    }

    /// The inverse map on a block of directions (`HdsCore::invert`).
    #[inline(always)]
    pub(crate) fn invert_block<T: Lane>(
        &self,
        x: &[T; L],
        y: &[T; L],
        z: &[T; L],
        ou: &mut [T; L],
        ov: &mut [T; L],
    ) {
        let n = self.radial.n;
        let (xr, p) = radius_azimuth(x, y, z);
        let (i, i1, eps) = self.sectors(&p);
        let seg = self.segments_of(&xr);
        let (mut x0, mut x1, mut idx, mut da0, mut da1, mut db0, mut db1) = (
            [T::ZERO; L],
            [T::ZERO; L],
            [T::ZERO; L],
            [T::ZERO; L],
            [T::ZERO; L],
            [T::ZERO; L],
            [T::ZERO; L],
        );
        let (mut ua, mut ub, mut uan, mut ubn) =
            ([T::ZERO; L], [T::ZERO; L], [T::ZERO; L], [T::ZERO; L]);
        let (mut cum0, mut cum1, mut beta, mut r2a, mut r2b) = (
            [T::ZERO; L],
            [T::ZERO; L],
            [T::ZERO; L],
            [T::ZERO; L],
            [T::ZERO; L],
        );
        for l in 0..L {
            let j = seg[l];
            let (a, b) = (i[l] * n, i1[l] * n);
            // Windows of the rows and of the sector's entries: one bounds check per window.
            let xw = &self.radial.x[j..][..2];
            x0[l] = c(xw[0]);
            x1[l] = c(xw[1]);
            idx[l] = c(self.radial.inv_dx[j]);
            let (dwa, dwb) = (&self.radial.d[a + j..][..2], &self.radial.d[b + j..][..2]);
            da0[l] = c(dwa[0]);
            da1[l] = c(dwa[1]);
            db0[l] = c(dwb[0]);
            db1[l] = c(dwb[1]);
            let (uwa, uwb) = (&self.radial.u[a..][..n], &self.radial.u[b..][..n]);
            ua[l] = c(uwa[j]);
            ub[l] = c(uwb[j]);
            uan[l] = c(self.radial.total[i[l]]);
            ubn[l] = c(self.radial.total[i1[l]]);
            let s = i[l];
            let (cw, rw) = (&self.angular.cum[s..][..2], &self.angular.r2[s..][..2]);
            cum0[l] = c(cw[0]);
            cum1[l] = c(cw[1]);
            beta[l] = c(self.angular.beta[s]);
            r2a[l] = c(rw[0]);
            r2b[l] = c(rw[1]);
        }
        let kappa: T = c(self.angular.kappa);
        for l in 0..L {
            let e = eps[l];
            let d0 = (T::ONE - e) * da0[l] + e * db0[l];
            let d1 = (T::ONE - e) * da1[l] + e * db1[l];
            let k = (d1 - d0) * idx[l];
            let tau = (xr[l] - x0[l]).clamp(T::ZERO, x1[l] - x0[l]);
            let w = (T::ONE - e) * ua[l] + e * ub[l] + partial_mass(x0[l], d0, k, tau);
            let wn = (T::ONE - e) * uan[l] + e * ubn[l];
            let rb = if wn > T::ZERO {
                (w / wn).clamp(T::ZERO, T::ONE).sqrt()
            } else {
                T::ZERO
            };
            // angular::wedge_angle
            let wedge = beta[l] * e * (r2a[l] + T::HALF * (r2b[l] - r2a[l]) * e);
            let phib = (cum0[l] + kappa * wedge).min(cum1[l]);
            let (su, sv) = disk_to_square(rb, phib);
            ou[l] = su;
            ov[l] = sv;
        }
    }

    /// [`HdsCore::sample_block`] over slices of any (equal) length; the directions go to
    /// `x, y, z` and the disk density D to `d`.
    #[inline(always)]
    pub(crate) fn sample_slices<T: Lane>(&self, u: &[T], v: &[T], out: [&mut [T]; 4]) {
        let [x, y, z, d] = out;
        let len = u.len();
        let mut start = 0;
        while start < len {
            let cnt = (len - start).min(L);
            let (mut bu, mut bv) = ([c::<T>(PAD); L], [c::<T>(PAD); L]);
            bu[..cnt].copy_from_slice(&u[start..start + cnt]);
            bv[..cnt].copy_from_slice(&v[start..start + cnt]);
            let (mut bx, mut by, mut bz, mut bd) =
                ([T::ZERO; L], [T::ZERO; L], [T::ZERO; L], [T::ZERO; L]);
            self.sample_block(&bu, &bv, [&mut bx, &mut by, &mut bz, &mut bd]);
            x[start..start + cnt].copy_from_slice(&bx[..cnt]);
            y[start..start + cnt].copy_from_slice(&by[..cnt]);
            z[start..start + cnt].copy_from_slice(&bz[..cnt]);
            d[start..start + cnt].copy_from_slice(&bd[..cnt]);
            start += cnt;
        }
    }

    /// [`HdsCore::density_block`] over slices; the caller handles directions outside the map's
    /// hemisphere.
    #[inline(always)]
    pub(crate) fn density_slices<T: Lane>(&self, dir: [&[T]; 3], out: &mut [T]) {
        let len = out.len();
        let mut start = 0;
        while start < len {
            let cnt = (len - start).min(L);
            let mut b = [[T::ZERO; L], [T::ZERO; L], [T::ONE; L]];
            for (k, bk) in b.iter_mut().enumerate() {
                bk[..cnt].copy_from_slice(&dir[k][start..start + cnt]);
            }
            let mut o = [T::ZERO; L];
            self.density_block(&b[0], &b[1], &b[2], &mut o);
            out[start..start + cnt].copy_from_slice(&o[..cnt]);
            start += cnt;
        }
    }

    /// [`HdsCore::invert_block`] over slices.
    #[inline(always)]
    pub(crate) fn invert_slices<T: Lane>(&self, dir: [&[T]; 3], out: [&mut [T]; 2]) {
        let [u, v] = out;
        let len = u.len();
        let mut start = 0;
        while start < len {
            let cnt = (len - start).min(L);
            let mut b = [[T::ZERO; L], [T::ZERO; L], [T::ONE; L]];
            for (k, bk) in b.iter_mut().enumerate() {
                bk[..cnt].copy_from_slice(&dir[k][start..start + cnt]);
            }
            let (mut bu, mut bv) = ([T::ZERO; L], [T::ZERO; L]);
            self.invert_block(&b[0], &b[1], &b[2], &mut bu, &mut bv);
            u[start..start + cnt].copy_from_slice(&bu[..cnt]);
            v[start..start + cnt].copy_from_slice(&bv[..cnt]);
            start += cnt;
        }
    }
}

/// `mapping::guided_search` for a block: per lane, the largest i ≤ `last` with a_i ≤ x (0 if
/// none), for non-decreasing `a`, by a branch-free descent over the bracket of the guide table
/// (cell k covers [k, k + 1)/`scale`), then the scalar search's settling steps, entered only when
/// round-off left the answer outside the bracket.
#[inline(always)]
fn guided_block<T: Lane>(
    a: &[f64],
    guide: &[u32],
    scale: f64,
    xs: &[T; L],
    last: usize,
) -> [usize; L] {
    let kmax = guide.len() - 1;
    let (mut lo, mut hi, mut x) = ([0usize; L], [0usize; L], [0.0f64; L]);
    for l in 0..L {
        x[l] = xs[l].to_f64();
        let k = ((x[l] * scale) as usize).min(kmax);
        lo[l] = (guide[k] as usize).min(last);
        hi[l] = if k < kmax {
            (guide[k + 1] as usize).min(last)
        } else {
            last
        };
    }
    let mut found = descend(&lo, &hi, &x, |_, i| a[i]);
    for l in 0..L {
        found[l] = settle_guided(a, found[l], x[l], last);
    }
    found
}

/// The scalar search's settling steps after a guided descent (entered only when round-off left
/// `i` outside its bracket): the largest i ≤ `last` with a_i ≤ x, from a nearby start.
#[inline(always)]
pub(super) fn settle_guided(a: &[f64], mut i: usize, x: f64, last: usize) -> usize {
    while i > 0 && a[i] > x {
        i -= 1;
    }
    while i < last && a[i + 1] <= x {
        i += 1;
    }
    i
}

/// The scalar path's three settling loops of the radial search at the descent's answer `j`
/// (each entered only when its condition holds, rarely): Ũ_j and Ũ_{j+1} (`ut`) are read once in
/// the usual case. Returns the segment j and Ũ_j.
#[inline(always)]
pub(super) fn settle_radial<T: Lane>(
    mut j: usize,
    n: usize,
    w: T,
    ut: impl Fn(usize) -> T,
) -> (usize, T) {
    let (mut uj, mut uj1) = (ut(j), ut(j + 1));
    if j > 0 && uj > w {
        while j > 0 && ut(j) > w {
            j -= 1;
        }
        (uj, uj1) = (ut(j), ut(j + 1));
    }
    if j + 2 < n && uj1 <= w {
        while j + 2 < n && ut(j + 1) <= w {
            j += 1;
        }
        (uj, uj1) = (ut(j), ut(j + 1));
    }
    // The square's edge before an unlit zone at the end of the map (as Radial::forward).
    if j > 0 && uj1 <= uj {
        while j > 0 && ut(j + 1) <= ut(j) {
            j -= 1;
        }
        uj = ut(j);
    }
    (j, uj)
}

/// Per lane, the largest index j in [lo, hi] with `probe(lane, j)` ≤ `w` (lo itself when none is:
/// the caller settles that case), for a probe non-decreasing in j. Branch-free: the offset from lo
/// is built bit by bit from the highest bit of the block's widest bracket down, the same steps for
/// every lane, so the loop count is the block's and a lane never mispredicts a comparison.
#[inline(always)]
fn descend<T: PartialOrd + Copy>(
    lo: &[usize; L],
    hi: &[usize; L],
    w: &[T; L],
    probe: impl Fn(usize, usize) -> T,
) -> [usize; L] {
    let mut span = 0;
    for l in 0..L {
        span = span.max(hi[l].saturating_sub(lo[l]));
    }
    let mut base = *lo;
    if span == 0 {
        return base;
    }
    let mut h = 1usize << (usize::BITS - 1 - span.leading_zeros());
    while h > 0 {
        for l in 0..L {
            let cand = (base[l] + h).min(hi[l].max(lo[l]));
            // A conditional move, never a branch (LLVM would otherwise turn it into one).
            base[l] = std::hint::select_unpredictable(probe(l, cand) <= w[l], cand, base[l]);
        }
        h >>= 1;
    }
    base
}

/// `concentric::disk_to_square`, branch-free.
#[inline(always)]
fn disk_to_square<T: Lane>(r: T, phi: T) -> (T, T) {
    let p = if phi >= c(7.0 * FRAC_PI_4) {
        phi - c(TAU)
    } else {
        phi
    };
    let s = r * c::<T>(4.0 / PI);
    let (a, b) = if p < c(FRAC_PI_4) {
        (r, s * p)
    } else if p < c(3.0 * FRAC_PI_4) {
        (-(p - c(FRAC_PI_2)) * s, r)
    } else if p < c(5.0 * FRAC_PI_4) {
        (-r, -s * (p - c(PI)))
    } else {
        ((p - c(1.5 * PI)) * s, -r)
    };
    (
        (T::HALF * (a + T::ONE)).clamp(T::ZERO, T::ONE),
        (T::HALF * (b + T::ONE)).clamp(T::ZERO, T::ONE),
    )
}

/// `radial::solve_radius` on a block: every lane runs the scalar iteration (Halley safeguarded by
/// bisection, the same stopping rules), masked once it has stopped.
#[inline(always)]
fn solve_radius_block<T: Lane>(
    x0: &[T; L],
    x1: &[T; L],
    d0: &[T; L],
    d1: &[T; L],
    m: &[T; L],
) -> [T; L] {
    let mut tau = [T::ZERO; L];
    let mut lo = [T::ZERO; L];
    let mut hi = [T::ZERO; L];
    let mut k = [T::ZERO; L];
    let mut active = [false; L];
    let mut iterated = [false; L];
    let mut res = [T::ZERO; L];
    for l in 0..L {
        let h = x1[l] - x0[l];
        let kk = (d1[l] - d0[l]) / h;
        let dbar = T::HALF * (d0[l] + d1[l]);
        let q = m[l] / dbar;
        let t = q / ((x0[l] * x0[l] + q).sqrt() + x0[l]);
        let early = !(m[l] > T::ZERO) || !(h > T::ZERO) || !(dbar > T::ZERO);
        let konst = kk == T::ZERO;
        res[l] = if early {
            x0[l]
        } else if konst {
            x0[l] + t.min(h)
        } else {
            T::ZERO
        };
        active[l] = !early && !konst;
        iterated[l] = active[l];
        k[l] = kk;
        hi[l] = h;
        // radial::area_guess
        let ka = (d1[l] - d0[l]) / (h * (x0[l] + x1[l]));
        let ds = T::TWO * m[l] / (d0[l] + (d0[l] * d0[l] + T::TWO * ka * m[l]).max(T::ZERO).sqrt());
        let g = ds / (x0[l] + (x0[l] * x0[l] + ds).sqrt());
        // Not finite where 2Km underflows with d0 = 0: the constant-density guess t instead.
        let g = if g.is_finite() { g } else { t };
        tau[l] = g.clamp(T::ZERO, h);
    }
    for _ in 0..60 {
        if !active.iter().any(|&a| a) {
            break;
        }
        for l in 0..L {
            let (x0, k, t) = (x0[l], k[l], tau[l]);
            let f = partial_mass(x0, d0[l], k, t) - m[l];
            let exact = f == T::ZERO;
            let (nlo, nhi) = if f > T::ZERO { (lo[l], t) } else { (t, hi[l]) };
            let xx = x0 + t;
            let dd = d0[l] + k * t;
            let g1 = T::TWO * xx * dd;
            let g2 = T::TWO * (dd + k * xx);
            let den = g1 * g1 - T::HALF * f * g2;
            let next = if g1 > T::ZERO && den > T::ZERO {
                t - f * g1 / den
            } else {
                T::NAN
            };
            let halley = next > nlo && next < nhi;
            let next = if halley { next } else { T::HALF * (nlo + nhi) };
            // f = 0: the root itself, kept (the scalar loop stops before updating anything).
            let next = if exact { t } else { next };
            let step = (next - t).abs();
            let scale = x0 + next;
            let mut stop = step <= T::STOP_STEP * scale || nhi - nlo <= T::STOP_STEP * (x0 + nhi);
            let cc = c::<T>(0.25) * g2 * g2 + (c::<T>(4.0) * k).abs() * g1 * c::<T>(1.0 / 6.0);
            let predicted = cc * (step * step * step) <= T::STOP_CUBIC * scale * (g1 * g1);
            stop = stop || exact || (halley && step <= T::HALLEY_SMALL * scale && predicted);
            let a = active[l];
            let (nlo, nhi) = if exact { (lo[l], hi[l]) } else { (nlo, nhi) };
            tau[l] = if a { next } else { t };
            lo[l] = if a { nlo } else { lo[l] };
            hi[l] = if a { nhi } else { hi[l] };
            active[l] = a && !stop;
        }
    }
    for l in 0..L {
        res[l] = if iterated[l] { x0[l] + tau[l] } else { res[l] };
    }
    res
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mapping::radial::solve_radius;

    /// The lanes' radial solve equals the scalar one bit for bit (f64), on ordinary segments and
    /// on one whose linear-in-area guess underflows (d0 = 0, densities ~1e-306: the guess is
    /// not finite and the constant-density guess must be used, as in `radial::area_guess`).
    #[test]
    fn radial_solve_lanes_equal_scalar() {
        let mut segs = vec![(
            7.584728575995813e-1,
            1.0,
            0.0,
            1.348951026719991e-306,
            1.0491368806029343e-308,
        )];
        let mut state = 12345u64;
        let mut rnd = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        for _ in 0..63 {
            let x0 = rnd() * 0.9;
            let x1 = x0 + rnd() * 0.1 + 1e-3;
            let (d0, d1) = (rnd().powi(4) + 1e-3, rnd().powi(4) + 1e-3);
            let mass = crate::mapping::radial::segment_mass(x0, x1, d0, d1);
            segs.push((x0, x1, d0, d1, rnd() * mass));
        }
        for block in segs.chunks(L) {
            let get = |k: usize| -> [f64; L] {
                let mut a = [0.0; L];
                for (l, s) in block.iter().enumerate() {
                    a[l] = [s.0, s.1, s.2, s.3, s.4][k];
                }
                a
            };
            let got = solve_radius_block(&get(0), &get(1), &get(2), &get(3), &get(4));
            for (l, s) in block.iter().enumerate() {
                let want = solve_radius(s.0, s.1, s.2, s.3, s.4);
                assert!(want.is_finite() && want < s.1 || s.4 <= 0.0);
                assert_eq!(got[l].to_bits(), want.to_bits(), "segment {s:?}");
            }
        }
    }
}
