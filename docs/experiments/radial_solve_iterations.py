#!/usr/bin/env python3
"""Iterations of the radial solve (M_D, `radial::solve_radius`) per starting guess, on random
segments: a line-for-line model of the Rust iteration in float64 (Python floats), used to choose
the guess. Densities r**4 + 1e-3 (r uniform), as the side-by-side benchmark's grids; parallels
uniform in θ on 0..90°; the mass target uniform over the segment's mass.

    python3 docs/experiments/radial_solve_iterations.py

Prints, per grid and variant, the mean iterations per solve, the worst, the share of bisection
steps and the mean over blocks of 8 solves of the block's largest count (what a masked SIMD block
waits for). Variants: `const` = the constant-density start used until 2026-12 with its f = 0
bisection walk-off; `area` = the linear-in-area start with the f = 0 exit (the current code).
"""
import math
import random


def partial_mass(x0, d0, k, t):
    return t * (2 * x0 * d0 + t * ((x0 * k + d0) + t * (2 / 3) * k))


def solve(x0, x1, d0, d1, m, variant):
    h = x1 - x0
    k = (d1 - d0) / h
    dbar = 0.5 * (d0 + d1)
    if variant == "const":
        q = m / dbar
        tau = q / (math.sqrt(x0 * x0 + q) + x0)
    else:
        kk = (d1 - d0) / (h * (x0 + x1))
        ds = 2 * m / (d0 + math.sqrt(max(d0 * d0 + 2 * kk * m, 0.0)))
        tau = ds / (x0 + math.sqrt(x0 * x0 + ds))
    lo, hi = 0.0, h
    tau = min(max(tau, lo), hi)
    it = bis = 0
    for _ in range(60):
        it += 1
        f = partial_mass(x0, d0, k, tau) - m
        if f == 0 and variant == "area":
            break
        if f > 0:
            hi = tau
        else:
            lo = tau
        xx, dd = x0 + tau, d0 + k * tau
        g1, g2 = 2 * xx * dd, 2 * (dd + k * xx)
        den = g1 * g1 - 0.5 * f * g2
        nxt = tau - f * g1 / den if (g1 > 0 and den > 0) else float("nan")
        halley = lo < nxt < hi
        if not halley:
            nxt = 0.5 * (lo + hi)
            bis += 1
        step = abs(nxt - tau)
        tau = nxt
        scale = x0 + tau
        if step <= 1e-15 * scale or hi - lo <= 1e-15 * (x0 + hi):
            break
        if halley and step <= 1e-5 * scale:
            c = 0.25 * g2 * g2 + abs(4 * k) * g1 / 6
            if c * step ** 3 <= 1e-17 * scale * g1 * g1:
                break
    return it, bis


def main():
    print("parallels | start | mean iterations | worst | bisection steps per solve | mean block-of-8 max")
    for n in (19, 181, 1024):
        xs = [math.sqrt(1 - math.cos(math.radians(90 * j / (n - 1)))) for j in range(n)]
        for variant in ("const", "area"):
            rng = random.Random(2)
            its, worst, bis, blocks, cur = 0, 0, 0, [], []
            count = 20000
            for _ in range(count):
                j = rng.randrange(n - 1)
                x0, x1 = xs[j], xs[j + 1]
                d0, d1 = rng.random() ** 4 + 1e-3, rng.random() ** 4 + 1e-3
                mass = (x1 - x0) / 3 * (d0 * (2 * x0 + x1) + d1 * (x0 + 2 * x1))
                it, b = solve(x0, x1, d0, d1, rng.random() * mass, variant)
                its += it
                worst = max(worst, it)
                bis += b
                cur.append(it)
                if len(cur) == 8:
                    blocks.append(max(cur))
                    cur = []
            print(f"{n} | {variant} | {its / count:.2f} | {worst} | {bis / count:.4f} | "
                  f"{sum(blocks) / len(blocks):.2f}")


if __name__ == "__main__":
    main()
