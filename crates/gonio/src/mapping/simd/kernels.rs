//! The vector kernels of the HDS map (forward map, pdf, inverse), written once over a small
//! vocabulary of vector operations (`splat`, `add`, `gather`, `sel`, …) that each backend defines
//! for its own element, value, index and mask types and then instantiates with
//! [`vector_kernels!`]: in f64 [`super::portable`] (arrays of eight lanes, the baseline
//! instruction set), [`super::avx2`] (four `__m256d` per value) and [`super::avx512`] (two or
//! four `__m512d`); in f32 (the float32 map) [`super::portable`], [`super::avx2`] and
//! [`super::avx512`].
//!
//! The body is generic in the element type `E` that the vocabulary names: tables are `&[E]`,
//! constants are written as f64 and `splat` rounds them to `E`, and what depends on the precision
//! (the sin/cos reduction and series lengths, the atan2 series and table, the radial solve's
//! stopping rules) is read as `E::NAME` from [`crate::mapping::simd::math::Precision`]. The f64
//! instantiation performs exactly the operations it did before the body became generic. The macro stamps the
//! backend's `#[target_feature]` attribute on the entry points and small helpers; the bodies are
//! the same tokens for every backend. See [`super::avx2`] for the design, the exactness argument
//! and the measurements.
//!
//! Each stage of the map exists twice in the crate: its scalar reference in the stage module
//! (`concentric`, `angular`, `radial`, `lift`) and its vector form here, in the same operation
//! order (so the f64 results are the scalar ones bit for bit except through sin/cos and atan2).

// Lane loops index several arrays by the same lane number on purpose (they vectorise).
#![allow(clippy::needless_range_loop)]

/// The scalar search's settling steps after a guided descent (entered only when round-off left
/// `i` outside its bracket): the largest i ≤ `last` with a_i ≤ x, from a nearby start.
#[inline(always)]
pub(crate) fn settle_guided<E: Copy + PartialOrd>(
    a: &[E],
    mut i: usize,
    x: E,
    last: usize,
) -> usize {
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
pub(crate) fn settle_radial<E: Copy + PartialOrd>(
    mut j: usize,
    n: usize,
    w: E,
    ut: impl Fn(usize) -> E,
) -> (usize, E) {
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

/// Defines, in the calling module, the forward, pdf and inverse kernels over the module's vector
/// vocabulary, their entry points compiled with `#[target_feature(enable = $feat)]` when a feature
/// string is given (none for the portable backend).
macro_rules! vector_kernels {
    ($($feat:literal)?) => {
        /// `a.max(b)` as Rust computes it on x86 (`maxnum`): `b` where `b > a` or `a` is NaN, else `a`.
        #[inline]
        $(#[target_feature(enable = $feat)])?
        fn fmax(a: F, b: F) -> F {
            sel(or(gt(b, a), isnan(a)), b, a)
        }
        /// `a.min(b)` as Rust computes it on x86 (`minnum`): `b` where `b < a` or `a` is NaN, else `a`.
        #[inline]
        $(#[target_feature(enable = $feat)])?
        fn fmin(a: F, b: F) -> F {
            sel(or(lt(b, a), isnan(a)), b, a)
        }
        /// `Lane::clamp` (NaN passes through).
        #[inline]
        $(#[target_feature(enable = $feat)])?
        fn clamp(x: F, lo: F, hi: F) -> F {
            let x = sel(lt(x, lo), lo, x);
            sel(gt(x, hi), hi, x)
        }
        /// Lanes with |a| < ∞ (not NaN, not ±∞).
        #[inline]
        $(#[target_feature(enable = $feat)])?
        fn is_finite(a: F) -> M {
            lt(abs(a), splat(f64::INFINITY))
        }

        /// Per lane the largest j in [lo, hi] with `probe(j)` ≤ `w` (lo when none is; the caller
        /// settles that case), for a probe non-decreasing in j. Branch-free: the offset from lo is
        /// built bit by bit from the highest bit of the block's widest bracket down, the same steps
        /// for every lane.
        #[inline(always)]
        unsafe fn descend(lo: I, hi: I, w: F, probe: impl Fn(I) -> F) -> I {
            let span = ilanes(imax(isub(hi, lo), izero()))
                .into_iter()
                .max()
                .unwrap_or(0);
            let mut base = lo;
            if span == 0 {
                return base;
            }
            let top = imax(hi, lo);
            let mut h = 1usize << (usize::BITS - 1 - span.leading_zeros());
            while h > 0 {
                let cand = imin(iadd(base, isplat(h)), top);
                base = isel(le(probe(cand), w), cand, base);
                h >>= 1;
            }
            base
        }

        /// `mapping::guided_search` for a block: per lane the largest i ≤ `last` with a_i ≤ x (0 if none) for
        /// non-decreasing `a`, from the guide table's bracket, then the settling steps (per lane, only
        /// where the vector check finds one needed).
        #[inline(always)]
        unsafe fn guided(a: &[E], guide: &[u32], scale: E, x: F, last: usize) -> I {
            let kmax = guide.len() - 1;
            let k = to_index(mul(x, splat(f64::from(scale))), kmax);
            let lastv = isplat(last);
            let lo = imin(gather_u32(guide, k), lastv);
            let below_top = igt(isplat(kmax), k);
            let hi = isel(
                below_top,
                imin(gather_u32(guide, iadd(k, isplat(1))), lastv),
                lastv,
            );
            let found = unsafe { descend(lo, hi, x, |j| gather(a, j)) };
            // Settling: i > 0 with a_i > x, or i < last with a_{i+1} ≤ x.
            let zero_i = izero();
            let down = and(igt(found, zero_i), gt(gather(a, found), x));
            let up = and(igt(lastv, found), le(gather(a, iadd(found, isplat(1))), x));
            if !any(or(down, up)) {
                return found;
            }
            let (mut f, xs) = (ilanes(found), flanes(x));
            for l in 0..BLOCK {
                f[l] = crate::mapping::simd::kernels::settle_guided(a, f[l], xs[l], last);
            }
            ifrom(f)
        }

        /// `math::sin_cos` on the lanes, operation for operation (in f32 with the f32 reduction
        /// constants and series lengths of [`crate::mapping::simd::math::Precision`]).
        #[inline(always)]
        unsafe fn sin_cos(x: F) -> (F, F) {
            let magic = splat(E::ROUND_MAGIC);
            let [p1, p2, p3] = E::PIO2_PARTS;
            let k = sub(add(mul(x, splat(std::f64::consts::FRAC_2_PI)), magic), magic);
            let r = sub(sub(sub(x, mul(k, splat(p1))), mul(k, splat(p2))), mul(k, splat(p3)));
            let z = mul(r, r);
            let (ss, cs) = (E::SIN_SERIES, E::COS_SERIES);
            let mut ps = splat(ss[ss.len() - 1]);
            let mut pc = splat(cs[cs.len() - 1]);
            for k in (0..ss.len() - 1).rev() {
                ps = add(mul(ps, z), splat(ss[k]));
                pc = add(mul(pc, z), splat(cs[k]));
            }
            let s = add(r, mul(mul(r, z), ps));
            let one = splat(1.0);
            let hz = mul(splat(0.5), z);
            let w = sub(one, hz);
            let c = add(w, add(sub(sub(one, w), hz), mul(mul(z, z), pc)));
            let k4 = mul(k, splat(0.25));
            let n = sub(add(k4, magic), magic);
            let q = sub(k, mul(splat(4.0), sel(gt(n, k4), sub(n, one), n)));
            let (q1, q2, q3) = (eq(q, one), eq(q, splat(2.0)), eq(q, splat(3.0)));
            let swap = or(q1, q3);
            let (s1, c1) = (sel(swap, c, s), sel(swap, s, c));
            let sin = sel(or(q2, q3), neg(s1), s1);
            let cos = sel(or(q1, q2), neg(c1), c1);
            (sin, cos)
        }

        /// `math::atan2` on the lanes, operation for operation (its `atan_unit` inlined).
        #[inline(always)]
        unsafe fn atan2(y: F, x: F) -> F {
            let (z0, one) = (zero(), splat(1.0));
            let (ax, ay) = (abs(x), abs(y));
            let swap = gt(ay, ax);
            let (num, den) = (sel(swap, ax, ay), sel(swap, ay, ax));
            let t = sel(gt(den, z0), div(num, den), z0);
            // atan_unit(t)
            let t8 = mul(t, splat(8.0));
            let magic = splat(E::ROUND_MAGIC);
            let kf = sub(add(t8, magic), magic);
            let kf = sel(gt(kf, t8), sub(kf, one), kf);
            let c = mul(kf, splat(0.125));
            let z = div(sub(t, c), add(one, mul(t, c)));
            let z2 = mul(z, z);
            let at = E::ATAN_SERIES;
            let mut p = splat(at[at.len() - 1]);
            for k in (0..at.len() - 1).rev() {
                p = add(mul(p, z2), splat(at[k]));
            }
            let k = to_index(kf, 8);
            let (hi, lo) = (gather(&E::ATAN_HI, k), gather(&E::ATAN_LO, k));
            let a = add(hi, add(lo, add(z, mul(mul(z, z2), p))));
            let a = sel(swap, add(sub(splat(FRAC_PI_2), a), splat(E::HALF_PI_LO)), a);
            let a = sel(sign_negative(x), add(sub(splat(PI), a), splat(E::PI_LO_PART)), a);
            sel(sign_negative(y), neg(a), a)
        }

        /// `concentric::disk_to_square`, branch-free (selects).
        #[inline(always)]
        unsafe fn disk_to_square(r: F, phi: F) -> (F, F) {
            let (z0, one, half) = (zero(), splat(1.0), splat(0.5));
            let p = sel(ge(phi, splat(7.0 * FRAC_PI_4)), sub(phi, splat(TAU)), phi);
            let s = mul(r, splat(4.0 / PI));
            let q0 = lt(p, splat(FRAC_PI_4));
            let q1 = lt(p, splat(3.0 * FRAC_PI_4));
            let q2 = lt(p, splat(5.0 * FRAC_PI_4));
            let a = sel(
                q0,
                r,
                sel(
                    q1,
                    mul(neg(sub(p, splat(FRAC_PI_2))), s),
                    sel(q2, neg(r), mul(sub(p, splat(1.5 * PI)), s)),
                ),
            );
            let b = sel(
                q0,
                mul(s, p),
                sel(q1, r, sel(q2, mul(neg(s), sub(p, splat(PI))), neg(r))),
            );
            (
                clamp(mul(half, add(a, one)), z0, one),
                clamp(mul(half, add(b, one)), z0, one),
            )
        }

        /// `radial::partial_mass`, same operation order.
        #[inline]
        $(#[target_feature(enable = $feat)])?
        fn partial_mass(x0: F, d0: F, k: F, tau: F) -> F {
            let two = splat(2.0);
            mul(
                tau,
                add(
                    mul(mul(two, x0), d0),
                    mul(
                        tau,
                        add(add(mul(x0, k), d0), mul(mul(tau, splat(2.0 / 3.0)), k)),
                    ),
                ),
            )
        }

        /// `radial::solve_radius` on a block: every lane runs the scalar iteration (Halley safeguarded
        /// by bisection, the same stopping rules), masked once it has stopped.
        #[inline(always)]
        unsafe fn solve_radius(x0: F, x1: F, d0: F, d1: F, m: F) -> F {
            let (z, one, two, half) = (zero(), splat(1.0), splat(2.0), splat(0.5));
            let h = sub(x1, x0);
            let kk = div(sub(d1, d0), h);
            let dbar = mul(half, add(d0, d1));
            let early = or(or(not(gt(m, z)), not(gt(h, z))), not(gt(dbar, z)));
            let konst = eq(kk, z);
            let mut active = and(not(early), not(konst));
            let iterated = active;
            let k = kk;
            let mut hi = h;
            let mut lo = z;
            // radial::area_guess
            let ka = div(sub(d1, d0), mul(h, add(x0, x1)));
            let ds = div(
                mul(two, m),
                add(d0, sqrt(fmax(add(mul(d0, d0), mul(mul(two, ka), m)), z))),
            );
            let g = div(ds, add(x0, sqrt(add(mul(x0, x0), ds))));
            let finite = is_finite(g);
            // The constant-density root t, needed only by a constant segment's lane or where the guess
            // is not finite (rare): two divisions and a square root skipped otherwise.
            let (res, g) = if any(and(not(early), or(konst, not(finite)))) {
                let q = div(m, dbar);
                let t = div(q, add(sqrt(add(mul(x0, x0), q)), x0));
                (
                    sel(early, x0, sel(konst, add(x0, fmin(t, h)), z)),
                    sel(finite, g, t),
                )
            } else {
                (x0, g)
            };
            let mut tau = clamp(g, z, h);
            let (stop_step, stop_cubic, halley_small) =
                (splat(E::STOP_STEP), splat(E::STOP_CUBIC), splat(E::HALLEY_SMALL));
            for _ in 0..60 {
                if !any(active) {
                    break;
                }
                let t = tau;
                let f = sub(partial_mass(x0, d0, k, t), m);
                let exact = eq(f, z);
                let pos = gt(f, z);
                let (nlo, nhi) = (sel(pos, lo, t), sel(pos, t, hi));
                let xx = add(x0, t);
                let dd = add(d0, mul(k, t));
                let g1 = mul(mul(two, xx), dd);
                let g2 = mul(two, add(dd, mul(k, xx)));
                let den = sub(mul(g1, g1), mul(mul(half, f), g2));
                let next = sel(
                    and(gt(g1, z), gt(den, z)),
                    sub(t, div(mul(f, g1), den)),
                    splat(f64::NAN),
                );
                let halley = and(gt(next, nlo), lt(next, nhi));
                let next = sel(halley, next, mul(half, add(nlo, nhi)));
                let next = sel(exact, t, next);
                let step = abs(sub(next, t));
                let scale = add(x0, next);
                let stop = or(
                    le(step, mul(stop_step, scale)),
                    le(sub(nhi, nlo), mul(stop_step, add(x0, nhi))),
                );
                let cc = add(
                    mul(mul(splat(0.25), g2), g2),
                    mul(mul(abs(mul(splat(4.0), k)), g1), splat(1.0 / 6.0)),
                );
                let predicted = le(
                    mul(cc, mul(mul(step, step), step)),
                    mul(mul(stop_cubic, scale), mul(g1, g1)),
                );
                let stop = or(
                    or(stop, exact),
                    and(and(halley, le(step, mul(halley_small, scale))), predicted),
                );
                let (nlo, nhi) = (sel(exact, lo, nlo), sel(exact, hi, nhi));
                tau = sel(active, next, t);
                lo = sel(active, nlo, lo);
                hi = sel(active, nhi, hi);
                active = and(active, not(stop));
            }
            let _ = one;
            sel(iterated, add(x0, tau), res)
        }

        /// The forward map on one block: directions and the disk density D (`HdsCore::sample`), in
        /// four stages whose costs `docs/PERFORMANCE.md` reports.
        #[inline]
        $(#[target_feature(enable = $feat)])?
        fn sample_block(c: &TablesView<'_, E>, u: F, v: F) -> [F; 4] {
            let (rb, pb, wi) = sample_stage_disk(c, u, v);
            let (phic, eps, a_off, b_off, j, uj, w) = sample_stage_search(c, rb, pb, wi);
            let seg = sample_stage_solve(c, eps, a_off, b_off, j, uj, w);
            sample_stage_lift(c, phic, seg)
        }

        /// Forward stage 1: M_B (concentric::square_to_disk, branch-free) and the wedge search.
        /// Returns r_B, φ_B and the wedge index.
        #[inline]
        $(#[target_feature(enable = $feat)])?
        fn sample_stage_disk(c: &TablesView<'_, E>, u: F, v: F) -> (F, F, I) {
            let ang = &c.angular;
            let (z, one, two) = (zero(), splat(1.0), splat(2.0));
            let a = sub(mul(two, u), one);
            let b = sub(mul(two, v), one);
            let big = gt(abs(a), abs(b));
            let (r, num, den) = (sel(big, a, b), sel(big, b, a), sel(big, a, b));
            let q = div(num, den);
            let quarter = splat(FRAC_PI_4);
            let phi = sel(big, mul(quarter, q), sub(splat(FRAC_PI_2), mul(quarter, q)));
            let negr = lt(r, z);
            let r = sel(negr, neg(r), r);
            let phi = sel(negr, add(phi, splat(PI)), phi);
            let phi = sel(lt(phi, z), add(phi, splat(TAU)), phi);
            let phi = sel(ge(phi, splat(TAU)), z, phi);
            let origin = and(eq(a, z), eq(b, z));
            let rb = sel(origin, z, r);
            let pb = sel(origin, z, phi);
            let wi = unsafe { guided(&ang.cum, &ang.wedge_guide, ang.guide_scale, pb, ang.m - 1) };
            (rb, pb, wi)
        }

        /// Forward stage 2: the wedge equation (angular::solve_wedge), then the radial search over
        /// the blended CDF of the wedge's two meridians. Returns φ_C, ε, the two meridians' table
        /// offsets, the segment j, its blended cumulative mass Ũ_j and the target mass w.
        #[inline]
        $(#[target_feature(enable = $feat)])?
        fn sample_stage_search(c: &TablesView<'_, E>, rb: F, pb: F, wi: I) -> (F, F, I, I, I, F, F) {
            let (ang, rad) = (&c.angular, &c.radial);
            let n = rad.n;
            let (z, one, two, half) = (zero(), splat(1.0), splat(2.0), splat(0.5));
            let beta = gather(&ang.beta, wi);
            let ra = gather(&ang.r2, wi);
            let rbb = gather(&ang.r2, iadd(wi, isplat(1)));
            let cum = gather(&ang.cum, wi);
            let phi0 = gather(&ang.phi, wi);
            let kappa = splat(f64::from(ang.kappa));
            let gamma = div(sub(pb, cum), kappa);
            let aa = mul(mul(half, beta), sub(rbb, ra));
            let bb = mul(beta, ra);
            let cc = fmax(gamma, z);
            let den = add(
                bb,
                sqrt(fmax(add(mul(bb, bb), mul(mul(splat(4.0), aa), cc)), z)),
            );
            let eps = sel(gt(den, z), clamp(div(mul(two, cc), den), z, one), z);
            let phic = add(phi0, mul(eps, beta));

            let w1 = iadd(wi, isplat(1));
            let wn = isel(ieq(w1, isplat(ang.m)), izero(), w1);
            let nv = isplat(n);
            let (a_off, b_off) = (imul(wi, nv), imul(wn, nv));
            let ome = sub(one, eps);
            let blend = |t: &[E], j: I| {
                add(
                    mul(ome, gather(t, iadd(a_off, j))),
                    mul(eps, gather(t, iadd(b_off, j))),
                )
            };
            let r2b = mul(rb, rb);
            let w = mul(
                r2b,
                add(
                    mul(ome, gather(&rad.total, wi)),
                    mul(eps, gather(&rad.total, wn)),
                ),
            );
            let kg = rad.radial_k;
            let kk = to_index(mul(r2b, splat(kg as f64)), kg - 1);
            let kgv = isplat(kg + 1);
            let ga = iadd(imul(wi, kgv), kk);
            let gb = iadd(imul(wn, kgv), kk);
            let rg = &rad.radial_guide;
            let lo = imin(gather_u32(rg, ga), gather_u32(rg, gb));
            let i1 = isplat(1);
            let hi = imax(gather_u32(rg, iadd(ga, i1)), gather_u32(rg, iadd(gb, i1)));
            let mut j = unsafe { descend(lo, hi, w, |j| blend(&rad.u, j)) };
            let mut uj = blend(&rad.u, j);
            let uj1 = blend(&rad.u, iadd(j, i1));
            // The scalar search's settling loops, redone per lane where any of their conditions holds.
            let zi = izero();
            let jpos = igt(j, zi);
            let settle = or(
                or(
                    and(jpos, gt(uj, w)),
                    and(igt(isplat(n), iadd(j, isplat(2))), le(uj1, w)),
                ),
                and(jpos, le(uj1, uj)),
            );
            if any(settle) {
                let (mut js, mut ujo) = (ilanes(j), flanes(uj));
                let (ws, es, ais, bis) = (flanes(w), flanes(eps), ilanes(a_off), ilanes(b_off));
                for l in 0..BLOCK {
                    let (e, wl) = (es[l], ws[l]);
                    let (ua, ub) = (&rad.u[ais[l]..ais[l] + n], &rad.u[bis[l]..bis[l] + n]);
                    let ut = |j: usize| (1.0 - e) * ua[j] + e * ub[j];
                    (js[l], ujo[l]) = crate::mapping::simd::kernels::settle_radial(js[l], n, wl, ut);
                }
                j = ifrom(js);
                uj = fload(&ujo);
            }
            (phic, eps, a_off, b_off, j, uj, w)
        }

        /// Forward stage 3: the radial solve on segment j. Returns the disk radius, x_j, 1/(x_{j+1} −
        /// x_j) and the blended segment-end densities d_j, d_{j+1}.
        #[inline]
        $(#[target_feature(enable = $feat)])?
        fn sample_stage_solve(
            c: &TablesView<'_, E>,
            eps: F,
            a_off: I,
            b_off: I,
            j: I,
            uj: F,
            w: F,
        ) -> [F; 5] {
            let rad = &c.radial;
            let ome = sub(splat(1.0), eps);
            let blend = |t: &[E], j: I| {
                add(
                    mul(ome, gather(t, iadd(a_off, j))),
                    mul(eps, gather(t, iadd(b_off, j))),
                )
            };
            let i1 = isplat(1);
            let d0 = blend(&rad.d, j);
            let d1 = blend(&rad.d, iadd(j, i1));
            let x0 = gather(&rad.x, j);
            let x1 = gather(&rad.x, iadd(j, i1));
            let inv_dx = gather(&rad.inv_dx, j);
            let m = sub(w, uj);
            let xr = unsafe { solve_radius(x0, x1, d0, d1, m) };
            [fmin(xr, x1), x0, inv_dx, d0, d1]
        }

        /// Forward stage 4: the density at the radius and M_E (lift::disk_to_sphere). Returns the
        /// direction and the disk density D at it.
        #[inline]
        $(#[target_feature(enable = $feat)])?
        fn sample_stage_lift(c: &TablesView<'_, E>, phic: F, seg: [F; 5]) -> [F; 4] {
            let [xr, x0, inv_dx, d0, d1] = seg;
            let rad = &c.radial;
            let n = rad.n;
            let (z, one, two) = (zero(), splat(1.0), splat(2.0));
            let north = fmax(splat(f64::from(rad.d[0])), z);
            let south = fmax(splat(f64::from(rad.d[n - 1])), z);
            let r2 = mul(xr, xr);
            let s = mul(xr, sqrt(fmax(sub(two, r2), z)));
            let (sp, cp) = unsafe { sin_cos(phic) };
            let ox = mul(s, cp);
            let oy = mul(s, sp);
            let oz = sub(one, r2);
            let up = gt(oz, z);
            let rd2 = sel(
                up,
                div(add(mul(ox, ox), mul(oy, oy)), add(one, oz)),
                sub(one, oz),
            );
            let xd = sqrt(fmin(fmax(rd2, z), two));
            let t = fmin(fmax(mul(sub(xd, x0), inv_dx), z), one);
            let od = fmax(add(d0, mul(sub(d1, d0), t)), z);
            let pole = and(eq(ox, z), eq(oy, z));
            let od = sel(pole, sel(up, north, south), od);
            [ox, oy, oz, od]
        }

        /// The disk radius and the azimuth of a block of directions (`lift::sphere_to_disk_radius` and `lift::sphere_to_disk_azimuth`).
        #[inline(always)]
        unsafe fn radius_azimuth(x: F, y: F, z: F) -> (F, F) {
            let (z0, one, two) = (zero(), splat(1.0), splat(2.0));
            let r2 = sel(
                gt(z, z0),
                div(add(mul(x, x), mul(y, y)), add(one, z)),
                sub(one, z),
            );
            let xr = sqrt(clamp(r2, z0, two));
            (xr, unsafe { azimuth(x, y) })
        }

        /// The azimuth φ = atan2(y, x) of a block of directions moved into [0, 2π), φ = 0
        /// where x = y = 0.
        #[inline(always)]
        unsafe fn azimuth(x: F, y: F) -> F {
            let z0 = zero();
            let phi = unsafe { atan2(y, x) };
            let phi = sel(lt(phi, z0), add(phi, splat(TAU)), phi);
            let phi = sel(ge(phi, splat(TAU)), z0, phi);
            let pole = and(eq(x, z0), eq(y, z0));
            sel(pole, z0, phi)
        }

        /// Sector, next meridian and ε of a block of azimuths (`Angular::sector`).
        #[inline(always)]
        unsafe fn sectors(c: &TablesView<'_, E>, p: F) -> (I, I, F) {
            let ang = &c.angular;
            let m = ang.m;
            let i = if ang.inv_uniform_beta > 0.0 {
                let i = to_index(mul(p, splat(f64::from(ang.inv_uniform_beta))), m - 1);
                // Round-off of the product: one step either way.
                let down = lt(p, gather(&ang.phi, i));
                let up = and(
                    and(not(down), igt(isplat(m), iadd(i, isplat(1)))),
                    ge(p, gather(&ang.phi, iadd(i, isplat(1)))),
                );
                let i = isel(down, isub(i, isplat(1)), i);
                isel(up, iadd(i, isplat(1)), i)
            } else {
                let ps = flanes(p);
                let mut o = [0usize; BLOCK];
                for l in 0..BLOCK {
                    o[l] = crate::diagram::segment(ang.phi, ps[l]);
                }
                ifrom(o)
            };
            let i1 = iadd(i, isplat(1));
            let i1 = isel(ieq(i1, isplat(m)), izero(), i1);
            let phi0 = gather(&ang.phi, i);
            let beta = gather(&ang.beta, i);
            let eps = clamp(div(sub(p, phi0), beta), zero(), splat(1.0));
            (i, i1, eps)
        }

        /// The disk density D at a block of directions (`HdsCore::density`).
        #[inline]
        $(#[target_feature(enable = $feat)])?
        fn density_block(c: &TablesView<'_, E>, x: F, y: F, z: F) -> F {
            let rad = &c.radial;
            let n = rad.n;
            let (z0, one) = (zero(), splat(1.0));
            let (xr, p) = unsafe { radius_azimuth(x, y, z) };
            let (i, i1, eps) = unsafe { sectors(c, p) };
            let j = unsafe { guided(&rad.x, &rad.radius_guide, rad.radius_scale, xr, n - 2) };
            let t = clamp(
                mul(sub(xr, gather(&rad.x, j)), gather(&rad.inv_dx, j)),
                z0,
                one,
            );
            let nv = isplat(n);
            let (a, b) = (iadd(imul(i, nv), j), iadd(imul(i1, nv), j));
            let i1v = isplat(1);
            let (a0, a1) = (gather(&rad.d, a), gather(&rad.d, iadd(a, i1v)));
            let (b0, b1) = (gather(&rad.d, b), gather(&rad.d, iadd(b, i1v)));
            let ra = add(a0, mul(t, sub(a1, a0)));
            let rb = add(b0, mul(t, sub(b1, b0)));
            let d = fmax(add(mul(sub(one, eps), ra), mul(eps, rb)), z0);
            let edge = splat(f64::from(rad.edge));
            sel(gt(xr, edge), z0, d)
        }

        /// The inverse map on a block of directions (`HdsCore::invert`).
        #[inline]
        $(#[target_feature(enable = $feat)])?
        fn invert_block(c: &TablesView<'_, E>, x: F, y: F, z: F) -> (F, F) {
            let (ang, rad) = (&c.angular, &c.radial);
            let n = rad.n;
            let (z0, one, half) = (zero(), splat(1.0), splat(0.5));
            let (xr, p) = unsafe { radius_azimuth(x, y, z) };
            let (i, i1, e) = unsafe { sectors(c, p) };
            let j = unsafe { guided(&rad.x, &rad.radius_guide, rad.radius_scale, xr, n - 2) };
            let i1v = isplat(1);
            let (x0, x1) = (gather(&rad.x, j), gather(&rad.x, iadd(j, i1v)));
            let idx = gather(&rad.inv_dx, j);
            let nv = isplat(n);
            let (ra, rb) = (imul(i, nv), imul(i1, nv));
            let (a, b) = (iadd(ra, j), iadd(rb, j));
            let (da0, da1) = (gather(&rad.d, a), gather(&rad.d, iadd(a, i1v)));
            let (db0, db1) = (gather(&rad.d, b), gather(&rad.d, iadd(b, i1v)));
            let (ua, ub) = (gather(&rad.u, a), gather(&rad.u, b));
            let (uan, ubn) = (gather(&rad.total, i), gather(&rad.total, i1));
            let (cum0, cum1) = (gather(&ang.cum, i), gather(&ang.cum, iadd(i, i1v)));
            let beta = gather(&ang.beta, i);
            let (r2a, r2b) = (gather(&ang.r2, i), gather(&ang.r2, iadd(i, i1v)));
            let ome = sub(one, e);
            let d0 = add(mul(ome, da0), mul(e, db0));
            let d1 = add(mul(ome, da1), mul(e, db1));
            let k = mul(sub(d1, d0), idx);
            let tau = clamp(sub(xr, x0), z0, sub(x1, x0));
            let w = add(add(mul(ome, ua), mul(e, ub)), partial_mass(x0, d0, k, tau));
            let wn = add(mul(ome, uan), mul(e, ubn));
            let rbd = sel(gt(wn, z0), sqrt(clamp(div(w, wn), z0, one)), z0);
            let wedge = mul(mul(beta, e), add(r2a, mul(mul(half, sub(r2b, r2a)), e)));
            let phib = fmin(add(cum0, mul(splat(f64::from(ang.kappa)), wedge)), cum1);
            unsafe { disk_to_square(rbd, phib) }
        }

        /// The block of `col[s..s + cnt]` (cnt ≤ BLOCK), lanes beyond `cnt` set to `pad`. A full
        /// block is loaded in place (no staging copy).
        #[inline(always)]
        unsafe fn load_block(col: &[E], s: usize, cnt: usize, pad: E) -> F {
            if let Ok(full) = <&[E; BLOCK]>::try_from(&col[s..s + cnt]) {
                fload(full)
            } else {
                let mut b = [pad; BLOCK];
                b[..cnt].copy_from_slice(&col[s..s + cnt]);
                fload(&b)
            }
        }

        /// The blocks of directions `dir[·][s..s + cnt]` (cnt ≤ BLOCK), lanes beyond `cnt` set to
        /// +z. Three calls, not `array::map` (whose closure the portable build left out of line).
        #[inline(always)]
        unsafe fn load_directions(dir: [&[E]; 3], s: usize, cnt: usize) -> (F, F, F) {
            unsafe {
                (
                    load_block(dir[0], s, cnt, 0.0),
                    load_block(dir[1], s, cnt, 0.0),
                    load_block(dir[2], s, cnt, 1.0),
                )
            }
        }

        /// Writes the first `cnt` lanes of `x` to `col[s..s + cnt]` (cnt ≤ BLOCK).
        #[inline(always)]
        unsafe fn store_block(col: &mut [E], s: usize, cnt: usize, x: F) {
            let lanes = flanes(x);
            if let Ok(full) = <&mut [E; BLOCK]>::try_from(&mut col[s..s + cnt]) {
                *full = lanes;
            } else {
                col[s..s + cnt].copy_from_slice(&lanes[..cnt]);
            }
        }

        /// [`density_block`] over slices.
        $(#[target_feature(enable = $feat)])?
        pub(crate) fn density_slices(c: &TablesView<'_, E>, dir: [&[E]; 3], out: &mut [E]) {
            let len = out.len();
            assert!(dir.iter().all(|c| c.len() == len));
            let mut start = 0;
            while start < len {
                let cnt = (len - start).min(BLOCK);
                let (x, y, z) = unsafe { load_directions(dir, start, cnt) };
                unsafe { store_block(out, start, cnt, density_block(c, x, y, z)) };
                start += cnt;
            }
        }

        /// [`invert_block`] over slices.
        $(#[target_feature(enable = $feat)])?
        pub(crate) fn invert_slices(c: &TablesView<'_, E>, dir: [&[E]; 3], out: [&mut [E]; 2]) {
            unsafe { pairs_of_directions(dir, out, |x, y, z| invert_block(c, x, y, z)) }
        }

        /// `f` of each block of the directions `dir`, its two results to `out[0]` and `out[1]`.
        #[inline(always)]
        unsafe fn pairs_of_directions(
            dir: [&[E]; 3],
            out: [&mut [E]; 2],
            f: impl Fn(F, F, F) -> (F, F),
        ) {
            let [a, b] = out;
            let len = a.len();
            assert!(b.len() == len && dir.iter().all(|c| c.len() == len));
            let mut start = 0;
            while start < len {
                let cnt = (len - start).min(BLOCK);
                let (x, y, z) = unsafe { load_directions(dir, start, cnt) };
                let (oa, ob) = f(x, y, z);
                unsafe {
                    store_block(a, start, cnt, oa);
                    store_block(b, start, cnt, ob);
                }
                start += cnt;
            }
        }

        /// Polar angle θ and azimuth φ of a block of directions, operation for operation as
        /// [`crate::mapping::simd::math::angles`] (so bit-identical to it): θ = atan2(√(x² + y²), z),
        /// φ = atan2(y, x) moved into [0, 2π), φ = 0 where x = y = 0.
        // Used by the f64 instantiations only (the environment map's eval); unused in f32.
        #[allow(dead_code)]
        #[inline(always)]
        unsafe fn angles_block(x: F, y: F, z: F) -> (F, F) {
            let rho = sqrt(add(mul(x, x), mul(y, y)));
            let theta = unsafe { atan2(rho, z) };
            (theta, unsafe { azimuth(x, y) })
        }

        /// [`angles_block`] over slices: θ to `out[0]`, φ to `out[1]`.
        #[allow(dead_code)]
        $(#[target_feature(enable = $feat)])?
        pub(crate) fn angles_slices(dir: [&[E]; 3], out: [&mut [E]; 2]) {
            unsafe { pairs_of_directions(dir, out, |x, y, z| angles_block(x, y, z)) }
        }

        /// [`sample_block`] over slices of any (equal) length; directions to `x, y, z`, the disk
        /// density D to `d`.
        $(#[target_feature(enable = $feat)])?
        pub(crate) fn sample_slices(c: &TablesView<'_, E>, u: &[E], v: &[E], out: [&mut [E]; 4]) {
            let [x, y, z, d] = out;
            let len = u.len();
            assert!(v.len() == len && x.len() == len && y.len() == len);
            assert!(z.len() == len && d.len() == len);
            let mut start = 0;
            while start < len {
                let cnt = (len - start).min(BLOCK);
                let (bu, bv) = unsafe {
                    (
                        load_block(u, start, cnt, 0.5),
                        load_block(v, start, cnt, 0.5),
                    )
                };
                let o = sample_block(c, bu, bv);
                for (col, ov) in [&mut *x, &mut *y, &mut *z, &mut *d].into_iter().zip(o) {
                    unsafe { store_block(col, start, cnt, ov) };
                }
                start += cnt;
            }
        }
    };
}
pub(super) use vector_kernels;
