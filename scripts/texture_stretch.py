#!/usr/bin/env python3
"""Sander et al.'s L2 stretch (texture -> surface, 1 = isometric) of the maps behind the HDS layout
on the unit sphere, by numerical Jacobians on a grid of texture points (docs/TEXTURE.md, "Stretch").

For an equal-area map sigma1 * sigma2 is constant, so L2^2 is the texture-area mean of
(sigma1^2 + sigma2^2) / (2 sigma1 sigma2). Points within 1e-4 of the concentric map's diagonals
(its kinks) are left out. Pure Python: `python3 scripts/texture_stretch.py [N]` (N x N points,
default 500; a few seconds).
"""
import math
import sys


def concentric(u, v):
    """Shirley-Chiu square [0,1]^2 -> unit disk (x, y)."""
    a, b = 2 * u - 1, 2 * v - 1
    if a == 0 and b == 0:
        return 0.0, 0.0
    if abs(a) > abs(b):
        r, p = a, math.pi / 4 * (b / a)
    else:
        r, p = b, math.pi / 2 - math.pi / 4 * (a / b)
    return r * math.cos(p), r * math.sin(p)


def lambert(x, y):
    """Unit disk -> upper hemisphere, equal-area (z = 1 - r^2)."""
    r2 = x * x + y * y
    s = math.sqrt(max(2 - r2, 0.0))
    return x * s, y * s, 1 - r2


def l2(f, keep, n, h=1e-7):
    acc, cnt = 0.0, 0
    for i in range(n):
        for j in range(n):
            u, v = (i + 0.5) / n, (j + 0.5) / n
            if not keep(u, v):
                continue
            p, pu, pv = f(u, v), f(u + h, v), f(u, v + h)
            ju = [(pu[k] - p[k]) / h for k in range(3)]
            jv = [(pv[k] - p[k]) / h for k in range(3)]
            a = sum(x * x for x in ju)
            c = sum(x * x for x in jv)
            b = sum(ju[k] * jv[k] for k in range(3))
            acc += (a + c) / 2 / math.sqrt(a * c - b * b)
            cnt += 1
    return math.sqrt(acc / cnt)


def off_diagonals(u, v):
    return abs(abs(2 * u - 1) - abs(2 * v - 1)) > 1e-4


def in_disk(u, v):
    return (2 * u - 1) ** 2 + (2 * v - 1) ** 2 < 0.999


if __name__ == "__main__":
    n = int(sys.argv[1]) if len(sys.argv) > 1 else 500
    sq = l2(lambda u, v: lambert(*concentric(u, v)), off_diagonals, n)
    disk = l2(lambda u, v: lambert(2 * u - 1, 2 * v - 1), in_disk, n)
    conc = l2(lambda u, v: (*concentric(u, v), 0.0), off_diagonals, n)
    print(f"concentric + Lambert, square chart (the HDS map of a uniform sphere): L2 = {sq:.4f}")
    print(f"Lambert alone, disk chart: L2 = {disk:.4f}; "
          f"over the whole square texture (x sqrt(4/pi)): {disk * math.sqrt(4 / math.pi):.4f}")
    print(f"concentric alone, square -> disk (planar): L2 = {conc:.4f}")
