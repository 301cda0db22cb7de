//! The batch (structure-of-arrays) kernels of one HDS map: [`HdsCore::sample`], `density` and
//! `invert` over blocks of [`LANES`] points (see [`crate::mapping::simd`] for how they are written).
//!
//! In f64 every arithmetic step is the scalar path's, in its order (so the results are the scalar
//! ones bit for bit except through sin/cos and atan2); in f32 the same steps run in f32 with the
//! tables read from their f64 values, while the table searches compare in f64 (exact for f32
//! inputs).

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
        if x[l] == T::ZERO && y[l] == T::ZERO {
            // The poles read meridian 0 (φ = 0), whatever the signs of the zeros.
            p[l] = T::ZERO;
            continue;
        }
        let mut phi = y[l].atan2(x[l]);
        phi = if phi < T::ZERO { phi + c(TAU) } else { phi };
        p[l] = if phi >= c(TAU) { T::ZERO } else { phi };
    }
    (xr, p)
}

impl HdsCore {
    /// Sector index of azimuth `p` (as `HdsCore::sector`, without ε).
    #[inline(always)]
    fn sector_index(&self, p: f64) -> usize {
        if self.angular.inv_uniform_beta > 0.0 {
            let mut i = ((p * self.angular.inv_uniform_beta) as usize).min(self.angular.m - 1);
            if p < self.angular.phi[i] {
                i -= 1;
            } else if p >= self.angular.phi[i + 1] && i + 1 < self.angular.m {
                i += 1;
            }
            i
        } else {
            crate::diagram::segment(&self.angular.phi, p)
        }
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
        for l in 0..L {
            let i = self.angular.wedge(pb[l].to_f64());
            wi[l] = i;
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
        for l in 0..L {
            let i = wi[l];
            let i1 = self.angular.next(i);
            let e = eps[l];
            let (ua, ub) = (
                &self.radial.u[i * n..i * n + n],
                &self.radial.u[i1 * n..i1 * n + n],
            );
            let ut = |j: usize| (T::ONE - e) * c::<T>(ua[j]) + e * c::<T>(ub[j]);
            let r2b = rb[l] * rb[l];
            let w = r2b * ut(n - 1);
            let k = (r2b * c::<T>(kg as f64)).to_usize().min(kg - 1);
            let (ga, gb) = (
                &self.radial.radial_guide[i * (kg + 1)..(i + 1) * (kg + 1)],
                &self.radial.radial_guide[i1 * (kg + 1)..(i1 + 1) * (kg + 1)],
            );
            let (mut lo, mut hi) = (ga[k].min(gb[k]) as usize, ga[k + 1].max(gb[k + 1]) as usize);
            while hi > lo {
                let mid = (lo + hi).div_ceil(2);
                if ut(mid) <= w {
                    lo = mid;
                } else {
                    hi = mid - 1;
                }
            }
            let mut j = lo;
            while j > 0 && ut(j) > w {
                j -= 1;
            }
            while j + 2 < n && ut(j + 1) <= w {
                j += 1;
            }
            // The square's edge before an unlit zone at the end of the map (as Radial::forward).
            while j > 0 && ut(j + 1) <= ut(j) {
                j -= 1;
            }
            let (da, db) = (
                &self.radial.d[i * n..i * n + n],
                &self.radial.d[i1 * n..i1 * n + n],
            );
            d0[l] = (T::ONE - e) * c::<T>(da[j]) + e * c::<T>(db[j]);
            d1[l] = (T::ONE - e) * c::<T>(da[j + 1]) + e * c::<T>(db[j + 1]);
            x0[l] = c(self.radial.x[j]);
            x1[l] = c(self.radial.x[j + 1]);
            inv_dx[l] = c(self.radial.inv_dx[j]);
            m[l] = w - ut(j);
        }
        let xr = solve_radius_block(&x0, &x1, &d0, &d1, &m);
        // Density at the radius and M_E (lift::disk_to_sphere).
        let [ox, oy, oz, od] = out;
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
            if ox[l] == T::ZERO && oy[l] == T::ZERO {
                // A pole: `density` reads meridian 0 there (φ = 0): parallel 0 at the north
                // pole, the last parallel at the south pole (the rim of the Lambert disk).
                let j = if oz[l] > T::ZERO { 0 } else { n - 1 };
                od[l] = c::<T>(self.radial.d[j]).max(T::ZERO);
            }
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
        let (mut t, mut a0, mut a1, mut b0, mut b1) = (
            [T::ZERO; L],
            [T::ZERO; L],
            [T::ZERO; L],
            [T::ZERO; L],
            [T::ZERO; L],
        );
        for l in 0..L {
            let j = self.radial.segment_of(xr[l].to_f64());
            let (xj, idx) = (c::<T>(self.radial.x[j]), c::<T>(self.radial.inv_dx[j]));
            t[l] = ((xr[l] - xj) * idx).clamp(T::ZERO, T::ONE);
            a0[l] = c(self.radial.d[i[l] * n + j]);
            a1[l] = c(self.radial.d[i[l] * n + j + 1]);
            b0[l] = c(self.radial.d[i1[l] * n + j]);
            b1[l] = c(self.radial.d[i1[l] * n + j + 1]);
        }
        for l in 0..L {
            let ra = a0[l] + t[l] * (a1[l] - a0[l]);
            let rb = b0[l] + t[l] * (b1[l] - b0[l]);
            out[l] = ((T::ONE - eps[l]) * ra + eps[l] * rb).max(T::ZERO);
            if xr[l].to_f64() > self.radial.x[n - 1] * (1.0 + 1e-12) {
                // Beyond the zone the map covers: no light (`HdsCore::density`).
                out[l] = T::ZERO;
            }
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
            let j = self.radial.segment_of(xr[l].to_f64());
            let (a, b) = (i[l] * n, i1[l] * n);
            x0[l] = c(self.radial.x[j]);
            x1[l] = c(self.radial.x[j + 1]);
            idx[l] = c(self.radial.inv_dx[j]);
            da0[l] = c(self.radial.d[a + j]);
            da1[l] = c(self.radial.d[a + j + 1]);
            db0[l] = c(self.radial.d[b + j]);
            db1[l] = c(self.radial.d[b + j + 1]);
            ua[l] = c(self.radial.u[a + j]);
            ub[l] = c(self.radial.u[b + j]);
            uan[l] = c(self.radial.u[a + n - 1]);
            ubn[l] = c(self.radial.u[b + n - 1]);
            let s = i[l];
            cum0[l] = c(self.angular.cum[s]);
            cum1[l] = c(self.angular.cum[s + 1]);
            beta[l] = c(self.angular.beta[s]);
            r2a[l] = c(self.angular.r2[s]);
            r2b[l] = c(self.angular.r2[s + 1]);
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
        tau[l] = t.clamp(T::ZERO, h);
    }
    for _ in 0..60 {
        if !active.iter().any(|&a| a) {
            break;
        }
        for l in 0..L {
            let (x0, k, t) = (x0[l], k[l], tau[l]);
            let f = partial_mass(x0, d0[l], k, t) - m[l];
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
            let step = (next - t).abs();
            let scale = x0 + next;
            let mut stop = step <= T::STOP_STEP * scale || nhi - nlo <= T::STOP_STEP * (x0 + nhi);
            let r = g2 / g1;
            let cc = c::<T>(0.25) * r * r + (c::<T>(4.0) * k).abs() / (c::<T>(6.0) * g1);
            let predicted = cc * step * step * step <= T::STOP_CUBIC * scale;
            stop = stop || (halley && step <= T::HALLEY_SMALL * scale && predicted);
            let a = active[l];
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
