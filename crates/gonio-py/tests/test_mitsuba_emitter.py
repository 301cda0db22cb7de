"""Proof by rendering of the Mitsuba 3 emitter ``gonio.mitsuba`` (docs/MITSUBA.md).

Scene: a diffuse floor (albedo ρ = 0.5, the plane z = 0) under a corpus luminaire, seen straight
down by a perspective camera at height H whose image plane is parallel to the floor, so that pixel
(r, c) covers exactly the floor square x ∈ −X + [c, c+1]·2X/RES, y ∈ X − [r+1, r]·2X/RES. The
floor's radiance is L = ρ E / π, so the rendered illuminance is E = π L / ρ; gonio's exact
figure is E(P) = I(ω)·|cos| / r² (I the file's bilinear interpolant, ω the luminaire's local
direction toward P), averaged over each pixel by a SUB × SUB midpoint rule.

Statistical errors (every bound at 5σ; fixed seeds):
* ``path`` with a point luminaire: next-event estimation is deterministic, the only noise is the
  pixel position jitter: σ_pixel² = Var_pixel(E) / spp with Var_pixel from the SUB × SUB grid.
* ``ptracer``: each particle carries the weight w = I/pdf ≤ w_max = target_power / lo (lo the
  sampler's guaranteed min of pdf / target_pdf); the estimate of a block of pixels receiving the
  flux μ_B has σ_B ≤ sqrt(w_max · μ_B / N) for N = spp · RES² particles; checked on 4 × 4 blocks.
* Flux: the mean of N ``sample_ray`` weights against the file's flux (the interpolant's
  integral, ``Diagram.flux``), σ from the weights' sample standard deviation.
* The luminous opening's visible luminance: ``eval`` is deterministic, so the pixels that see only
  the opening hold I(ω)/A_proj(ω) up to float32 round-off (1e-4 relative).

Both variants: ``scalar_rgb`` (small images: a Python call per ray) and ``llvm_ad_rgb`` (needs
libLLVM: DRJIT_LIBLLVM_PATH, which scripts/test-python.sh sets). Skipped visibly without
Mitsuba, the variant, or the corpus.
"""

import math

import numpy as np
import pytest

import gonio
from conftest import corpus_dir

RHO = 0.5
H = 10.0  # camera height
FILES = ["ies/lm63_2002_lithonia_wallwash_h90_270.ies", "ldt/isym0_ledil_strada_72x181.ldt"]
VARIANTS = ["scalar_rgb", "llvm_ad_rgb"]


def _corpus_file(rel):
    c = corpus_dir()
    if c is None or not (c / rel).is_file():
        pytest.skip(f"SKIPPED: corpus file {rel} not found (set GONIO_CORPUS)")
    return c / rel


@pytest.fixture(params=VARIANTS)
def mi(request):
    try:
        import mitsuba
    except Exception as e:
        pytest.skip(f"SKIPPED: Mitsuba 3 is not installed ({e}); pip install mitsuba")
    try:
        mitsuba.set_variant(request.param)
    except Exception as e:
        pytest.skip(f"SKIPPED: Mitsuba's {request.param} variant cannot start (libLLVM? DRJIT_LIBLLVM_PATH): {e}")
    import drjit as dr

    import gonio.mitsuba

    flags = [(f, dr.flag(f)) for f in (dr.JitFlag.SymbolicCalls, dr.JitFlag.SymbolicLoops)]
    gonio.mitsuba.register()  # turns both off in llvm_ad_rgb
    yield mitsuba
    for f, v in flags:  # leave the other test files Mitsuba's defaults
        dr.set_flag(f, v)


def _scalar(mi):
    return mi.variant().startswith("scalar")


def floor_scene(mi, lamp, integrator, spp, res, half, seed=0):
    fov = 2.0 * math.degrees(math.atan(half / H))
    d = {
        "type": "scene",
        "integrator": integrator,
        "sensor": {
            "type": "perspective",
            "fov": fov,
            "fov_axis": "x",
            "to_world": mi.ScalarTransform4f().look_at(origin=[0, 0, H], target=[0, 0, 0], up=[0, 1, 0]),
            "film": {"type": "hdrfilm", "width": res, "height": res, "rfilter": {"type": "box"},
                     "pixel_format": "rgb"},
            "sampler": {"type": "independent", "sample_count": spp, "seed": seed},
        },
        "floor": {"type": "rectangle", "to_world": mi.ScalarTransform4f().scale([3 * half, 3 * half, 1]),
                  "bsdf": {"type": "diffuse", "reflectance": {"type": "rgb", "value": [RHO] * 3}}},
    }
    d.update(lamp)
    return mi.load_dict(d)


def exact_floor(diagram, matrix, res, half, sub=16):
    """Per pixel: the mean and variance of E = I·|cos|/r² over the pixel (SUB × SUB midpoints)."""
    g = (np.arange(res * sub) + 0.5) / (res * sub) * 2 * half - half
    xx, yy = np.meshgrid(g, -g)
    p = np.stack([xx.ravel(), yy.ravel(), np.zeros(xx.size)], axis=1)
    R, t = matrix[:3, :3], matrix[:3, 3]
    v = p - t
    r = np.linalg.norm(v, axis=1)
    w = v / r[:, None]
    loc = w @ np.linalg.inv(R).T
    loc /= np.linalg.norm(loc, axis=1, keepdims=True)
    e = (diagram.intensity(loc) * np.abs(w[:, 2]) / r**2).reshape(res, sub, res, sub)
    return e.mean(axis=(1, 3)), e.var(axis=(1, 3))


def render_E(mi, scene):
    img = np.array(mi.render(scene), dtype=np.float64)
    assert np.allclose(img[:, :, 0], img[:, :, 1]) and np.allclose(img[:, :, 0], img[:, :, 2])
    return math.pi * img[:, :, 0] / RHO


def transforms(mi):
    T = mi.ScalarTransform4f
    return {
        "straight": T().translate([0.3, -0.2, 1.5]),
        # turned 90° about the vertical (C0 toward +y) and tilted 25°: the frame is tested.
        "rotated": T().translate([-0.2, 0.4, 1.5]) @ T().rotate([0, 0, 1], 90) @ T().rotate([math.sqrt(0.5), math.sqrt(0.5), 0.0], 25),
    }


@pytest.mark.parametrize("pose", ["straight", "rotated"])
@pytest.mark.parametrize("rel", FILES)
def test_path_floor_illuminance_matches_exact(mi, rel, pose):
    path = _corpus_file(rel)
    d = gonio.read(path)
    T = transforms(mi)[pose]
    res, half = (12, 2.0) if _scalar(mi) else (32, 2.0)
    spp = 8 if _scalar(mi) else 32
    scene = floor_scene(mi, {"lamp": {"type": "gonio", "filename": str(path), "to_world": T}},
                        {"type": "path", "max_depth": 2}, spp, res, half, seed=1)
    E = render_E(mi, scene)
    mean, var = exact_floor(d, np.array(T.matrix, dtype=np.float64), res, half)
    sigma = np.sqrt(var / spp)
    tol = 5.0 * sigma + 2e-4 * mean.max()
    bad = np.abs(E - mean) > tol
    assert mean.max() > 0 and not bad.any(), (
        f"{np.count_nonzero(bad)} of {bad.size} pixels off: worst {np.max(np.abs(E - mean) / tol):.2f}× tolerance")
    # The total (a guard against a uniformly wrong scale hidden inside the per-pixel bound).
    assert abs(E.sum() - mean.sum()) <= 5.0 * np.sqrt((sigma**2).sum()) + 2e-4 * mean.sum()


@pytest.mark.parametrize("pose", ["straight", "rotated"])
@pytest.mark.parametrize("rel", FILES)
def test_ptracer_floor_illuminance_matches_exact(mi, rel, pose):
    path = _corpus_file(rel)
    d = gonio.read(path)
    s = d.sampler("hds", "sphere")
    lo, _ = s.ratio_bound
    T = transforms(mi)[pose]
    res, half, spp = (8, 2.0, 32) if _scalar(mi) else (16, 2.0, 1024)
    scene = floor_scene(mi, {"lamp": {"type": "gonio", "filename": str(path), "to_world": T}},
                        {"type": "ptracer", "max_depth": 2}, spp, res, half, seed=2)
    E = render_E(mi, scene)
    mean, _ = exact_floor(d, np.array(T.matrix, dtype=np.float64), res, half)
    a_pix = (2 * half / res) ** 2
    n = spp * res * res
    w_max = s.target_power / lo
    b = 4
    Eb = E.reshape(res // b, b, res // b, b).sum(axis=(1, 3)) * a_pix  # flux into each block, lm
    mb = mean.reshape(res // b, b, res // b, b).sum(axis=(1, 3)) * a_pix
    sigma = np.sqrt(w_max * mb / n)
    tol = 5.0 * sigma + 1e-3 * mb
    assert mb.max() > 0 and np.all(np.abs(Eb - mb) <= tol), (
        f"blocks off: {np.round((Eb - mb) / np.maximum(sigma, 1e-30), 1)} sigma")
    assert abs(Eb.sum() - mb.sum()) <= 5.0 * np.sqrt(w_max * mb.sum() / n) + 1e-3 * mb.sum()


def _np(v):
    return np.asarray(v, dtype=np.float64).reshape(-1)


@pytest.mark.parametrize("shape", ["point", "opening"])
@pytest.mark.parametrize("rel", FILES)
def test_flux_from_sample_ray_matches_file(mi, rel, shape):
    """Mitsuba's own estimate of the emitted power: the mean of scene.sample_emitter_ray weights
    (emitter selection included) over N rays, against the diagram's flux in lumens."""
    if _scalar(mi):
        pytest.skip("the flux test draws 10⁵ rays at once: llvm_ad_rgb only (scalar draws one per call)")
    import gonio.mitsuba as gm

    path = _corpus_file(rel)
    d = gonio.read(path)
    T = transforms(mi)["rotated"]
    dims = dict(width=0.3, length=0.2, height=0.1) if shape == "opening" else {}
    lamp = gm.luminaire(path, to_world=T, shape=shape, scale=2.0, **dims)
    scene = mi.load_dict({"type": "scene", **lamp})
    n = 100_000
    rng = np.random.default_rng(7)
    u = rng.random((5, n)).astype(np.float32)
    f = mi.Float
    ray, w, _ = scene.sample_emitter_ray(f(0.0), f(u[0]), mi.Point2f(f(u[1]), f(u[2])),
                                         mi.Point2f(f(u[3]), f(u[4])), mi.Bool(True))
    w = _np(w[0])
    assert w.size == n
    est, sd = w.mean(), w.std() / math.sqrt(n)
    want = 2.0 * d.flux
    assert abs(est - want) <= 5.0 * sd + 1e-4 * want, f"flux {est:.6g} ± {sd:.2g} vs {want:.6g} lm"
    # The rays start at the luminaire: on the opening's box for an opening, at the centre for a point.
    o = np.stack([_np(ray.o.x), _np(ray.o.y), _np(ray.o.z)], axis=1)
    M = np.array(T.matrix, dtype=np.float64)
    local = (o - M[:3, 3]) @ M[:3, :3]
    lim = np.array([0.1, 0.15, 0.05]) + 1e-3 if shape == "opening" else np.full(3, 1e-5)
    assert np.all(np.abs(local) <= lim)


@pytest.mark.parametrize("rel", FILES)
def test_opening_visible_luminance(mi, rel):
    """An orthographic camera looking at the luminous opening (a 0.2 m × 0.3 m × 0.1 m box, by
    override) along −ω sees L = I(ω)/A_proj(ω) on every pixel: its 4 cm square view around the
    centre lies inside the box's projection (which contains the 5 cm ball about the centre)."""
    import gonio.mitsuba as gm

    path = _corpus_file(rel)
    d = gonio.read(path)
    T = transforms(mi)["rotated"]
    M = np.array(T.matrix, dtype=np.float64)
    o = gm.Opening("box", 0.2, 0.3, 0.1)
    res = 4 if _scalar(mi) else 16
    for local_view in ([0.3, -0.2, -0.93], [0.8, 0.5, -0.33], [-0.2, 0.1, -0.97], [0.0, 0.6, 0.8]):
        wl = np.array(local_view) / np.linalg.norm(local_view)
        ww = M[:3, :3] @ wl
        eye = M[:3, 3] + 3.0 * ww
        up = [0.0, 0.0, 1.0] if abs(ww[2]) < 0.9 else [1.0, 0.0, 0.0]
        scene = mi.load_dict({
            "type": "scene",
            "integrator": {"type": "path", "max_depth": 1},
            "sensor": {
                "type": "orthographic",
                "to_world": mi.ScalarTransform4f().look_at(origin=eye.tolist(), target=M[:3, 3].tolist(), up=up)
                @ mi.ScalarTransform4f().scale([0.02, 0.02, 1.0]),
                "film": {"type": "hdrfilm", "width": res, "height": res, "rfilter": {"type": "box"}},
                "sampler": {"type": "independent", "sample_count": 2},
            },
            **gm.luminaire(path, to_world=T, shape="opening", width=0.3, length=0.2, height=0.1),
        })
        img = np.array(mi.render(scene), dtype=np.float64)[:, :, 0]
        want = d.intensity(wl[None, :])[0] / o.projected_area(wl[None, :])[0]
        if want == 0:
            assert np.all(img == 0)
            continue
        assert np.all(np.abs(img / want - 1.0) <= 2e-4), (
            f"view {local_view}: luminance {img.min():.6g}..{img.max():.6g} vs {want:.6g} cd/m²")


@pytest.mark.parametrize("integrator", ["path", "ptracer"])
def test_opening_far_field_illuminance(mi, integrator):
    """A small opening (a 5 cm disk, by override) 4 m above the floor lights it as the point
    does, E = I(ω)·cos/r², up to the near-field term (a/r)² ~ 4e-5 and the disk's shadow on the
    camera's view of the floor (≤ 0.1 % of the central block), within the statistical error."""
    if _scalar(mi):
        pytest.skip("scalar: too slow for the particle count this needs; llvm_ad_rgb only")
    import gonio.mitsuba as gm

    path = _corpus_file(FILES[1])
    d = gonio.read(path)
    T = mi.ScalarTransform4f().translate([0.0, 0.0, 4.0]) @ mi.ScalarTransform4f().rotate([0, 0, 1], 30)
    res, half = 16, 6.0
    spp = 32 if integrator == "path" else 256
    lamp = gm.luminaire(path, to_world=T, shape="opening", width=-0.05, length=-0.05)
    scene = floor_scene(mi, lamp, {"type": integrator, "max_depth": 2}, spp, res, half, seed=3)
    E = render_E(mi, scene)
    mean, var = exact_floor(d, np.array(T.matrix, dtype=np.float64), res, half)
    a_pix = (2 * half / res) ** 2
    b = 4

    def blocks(x):
        return x.reshape(res // b, b, res // b, b).sum(axis=(1, 3))

    Eb, mb = blocks(E) * a_pix, blocks(mean) * a_pix
    if integrator == "path":
        # Pixel jitter (as for the point) plus next-event estimation on the disk, whose
        # per-sample weight varies by O(a/r) < 1 % across it.
        sigma = np.sqrt(blocks(var / spp + (0.01 * mean) ** 2 / spp)) * a_pix
    else:
        lo, _ = d.sampler("hds", "sphere").ratio_bound
        sigma = np.sqrt(d.flux / lo * mb / (spp * res * res))
    tol = 5.0 * sigma + 1e-3 * mb
    assert mb.max() > 0 and np.all(np.abs(Eb - mb) <= tol), (
        f"blocks off: {np.round((Eb - mb) / np.maximum(sigma, 1e-30), 1)} sigma; "
        f"rel {np.round(Eb / np.maximum(mb, 1e-30) - 1, 4)}")


@pytest.mark.parametrize("integrator", ["path", "ptracer"])
def test_opening_seen_from_afar_has_the_file_intensity(mi, integrator):
    """A pinhole camera 30 m away along ω sees the whole box opening (0.2 × 0.3 × 0.1 m): the
    image integrates to the irradiance at the pinhole, Σ L_pixel·Ω_pixel = I(ω)/d² up to the
    spread of the directions across the box (±0.4°, a second-order term ≲ 0.3 % here).
    ``path`` evaluates ``eval``; ``ptracer`` connects ``sample_position`` points to the camera
    (its direct view of emitters); both checked within 5.4 standard errors of 8 seeds (t, 7 dof;
    the pixels on the box's outline make the path image noisy too)."""
    if _scalar(mi):
        pytest.skip("scalar: the ptracer's direct view needs 10⁵ samples; llvm_ad_rgb only")
    import gonio.mitsuba as gm

    path = _corpus_file(FILES[1])
    d = gonio.read(path)
    T = transforms(mi)["rotated"]
    M = np.array(T.matrix, dtype=np.float64)
    res, fov, dist = 24, 1.0, 30.0
    lamp = gm.luminaire(path, to_world=T, shape="opening", width=0.3, length=0.2, height=0.1)
    for local_view in ([0.3, -0.2, -0.93], [0.8, 0.5, -0.33]):
        wl = np.array(local_view) / np.linalg.norm(local_view)
        ww = M[:3, :3] @ wl
        eye = M[:3, 3] + dist * ww
        sums = []
        for seed in range(8):
            scene = mi.load_dict({
                "type": "scene",
                "integrator": {"type": integrator, "max_depth": 1},
                "sensor": {
                    "type": "perspective", "fov": fov, "fov_axis": "x",
                    "to_world": mi.ScalarTransform4f().look_at(origin=eye.tolist(), target=M[:3, 3].tolist(),
                                                               up=[0.0, 0.0, 1.0]),
                    "film": {"type": "hdrfilm", "width": res, "height": res, "rfilter": {"type": "box"}},
                    "sampler": {"type": "independent", "sample_count": 64, "seed": seed},
                },
                **lamp,
            })
            img = np.array(mi.render(scene), dtype=np.float64)[:, :, 0]
            # Pixel solid angles of the pinhole: the image plane at distance 1 spans 2·tan(fov/2).
            s = 2.0 * math.tan(math.radians(fov) / 2.0) / res
            c = (np.arange(res) + 0.5 - res / 2.0) * s
            cx, cy = np.meshgrid(c, c)
            omega = s * s / (1.0 + cx**2 + cy**2) ** 1.5
            sums.append(float((img * omega).sum()))
        want = d.intensity(wl[None, :])[0] / dist**2
        got = float(np.mean(sums))
        se = float(np.std(sums, ddof=1) / math.sqrt(len(sums))) if len(sums) > 1 else 0.0
        assert want > 0 and abs(got - want) <= 5.4 * se + 3e-3 * want, (
            f"view {local_view}: irradiance {got:.6g} ± {se:.2g} vs I/d² = {want:.6g}")


@pytest.mark.parametrize("kind", ["box", "cylinder", "sphere", "disk"])
def test_opening_direction_pdf_agrees_with_mitsubas_geometry(mi, kind):
    """For each part: ``sample_direction`` from random reference points gives ds.pdf (solid
    angle); ``pdf_direction`` gives the same for that ds, and for the ds that Mitsuba builds from
    a ray it traced to the sampled point and hit on the part's shape (what ``path`` does under
    MIS); ``eval`` at that hit equals ``eval_direction``. Up to float32 geometry: 1e-4 for the
    recomputed pdf, 2e-3 for Mitsuba's own hit (its normals), away from grazing (cos > 0.1)."""
    if _scalar(mi):
        pytest.skip("a batch of 4096 reference points: llvm_ad_rgb only")
    import gonio.mitsuba as gm

    path = _corpus_file(FILES[0])
    T = transforms(mi)["rotated"]
    dims = {"box": (0.3, 0.2, 0.1), "cylinder": (-0.2, -0.2, 0.15), "sphere": (-0.2, -0.2, -0.2),
            "disk": (-0.3, -0.2, 0.0)}[kind]
    lamp = gm.luminaire(path, to_world=T, shape="opening", width=dims[0], length=dims[1], height=dims[2])
    scene = mi.load_dict({"type": "scene", **lamp})
    rng = np.random.default_rng(11)
    n = 4096
    M = np.array(T.matrix, dtype=np.float64)
    f = mi.Float
    checked = 0
    for em in scene.emitters():
        # Reference points 0.5–2 m from the luminaire in every direction.
        v = rng.normal(size=(n, 3))
        v *= rng.uniform(0.5, 2.0, size=(n, 1)) / np.linalg.norm(v, axis=1, keepdims=True)
        p = M[:3, 3] + v
        it = mi.Interaction3f()
        it.p = mi.Point3f(f(p[:, 0]), f(p[:, 1]), f(p[:, 2]))
        it.t = f(np.zeros(n))
        s = rng.random((n, 2))
        ds, w = em.sample_direction(it, mi.Point2f(f(s[:, 0]), f(s[:, 1])), mi.Bool(True))
        pdf = _np(ds.pdf)
        again = _np(em.pdf_direction(it, ds, mi.Bool(True)))
        ok = pdf > 0
        assert ok.mean() > 0.9
        # Not at grazing incidence, where the pdf (∝ 1/cos) amplifies float32 round-off.
        cos = np.abs(_np(ds.n.x) * _np(ds.d.x) + _np(ds.n.y) * _np(ds.d.y) + _np(ds.n.z) * _np(ds.d.z))
        ok &= cos > 0.1
        assert np.allclose(again[ok], pdf[ok], rtol=1e-4)
        # Trace toward the sampled point; keep the rays that hit this part near it, unoccluded.
        ray = mi.Ray3f(it.p, ds.d)
        si = scene.ray_intersect(ray)
        hit = _np(si.t)
        near = ok & np.isfinite(hit) & (np.abs(hit - _np(ds.dist)) < 1e-3 * _np(ds.dist))
        # On this part: the hit's normal is the sampled point's (not an adjacent face's at an edge).
        same = np.abs(_np(si.n.x) * _np(ds.n.x) + _np(si.n.y) * _np(ds.n.y) + _np(si.n.z) * _np(ds.n.z))
        near &= same > 0.999
        ds2 = mi.DirectionSample3f(scene, si, it)
        pdf2 = _np(em.pdf_direction(it, ds2, mi.Bool(True)))
        assert near.sum() > 0.3 * n
        rel = np.abs(pdf2[near] / pdf[near] - 1.0)
        assert rel.max() <= 2e-3, f"{kind}: pdf of the traced hit off by {rel.max():.2g} at {np.argmax(rel)}"
        # Radiance: eval at the traced hit (what path sees) equals eval_direction (what NEE
        # weighs), where the ray hit this part.
        Le = _np(em.eval(si, mi.Bool(True))[0])
        Ld = _np(em.eval_direction(it, ds, mi.Bool(True))[0])
        assert np.allclose(Le[near], Ld[near], rtol=1e-3, atol=1e-6 * max(Ld.max(), 1e-30))
        checked += 1
    assert checked == len(lamp)


@pytest.mark.parametrize("integrator", ["path", "ptracer"])
def test_opening_near_field_illuminance(mi, integrator):
    """A large opening close to the floor: a 0.6 m disk 0.8 m up at x = −2.2 m, tilted 40° toward
    the camera's patch of floor (outside the camera's view). Its illuminance E(P) =
    ∫ L(x, ω) |cos_x| cos_P / r² dA with L = I(ω)/(A |cos_x|) — here nothing like I·cos/r² —
    is integrated numerically (32 × 64 points on the disk, 2 × 2 per pixel) and compared with
    the renders by 4 × 4-pixel blocks: ``path`` mixes next-event estimation on the disk with
    BSDF rays that hit it (MIS: eval, pdf_direction), ``ptracer`` uses sample_ray. Bound: 5.4
    standard errors of 8 seeds (t, 7 dof) plus 0.5 % for the quadratures (a 3 % scale error fails
    both)."""
    if _scalar(mi):
        pytest.skip("8 seeds of a 16 × 16 image: llvm_ad_rgb only")
    import gonio.mitsuba as gm

    path = _corpus_file(FILES[0])
    d = gonio.read(path)
    T = mi.ScalarTransform4f().translate([-2.2, 0.0, 0.8]) @ mi.ScalarTransform4f().rotate([0, 1, 0], -40)
    M = np.array(T.matrix, dtype=np.float64)
    rad, res, half, sub = 0.3, 16, 1.5, 2
    lamp = gm.luminaire(path, to_world=T, shape="opening", width=-2 * rad, length=-2 * rad)
    # The reference: floor points P (sub × sub per pixel), disk points x (midpoints in r², φ).
    g = (np.arange(res * sub) + 0.5) / (res * sub) * 2 * half - half
    xx, yy = np.meshgrid(g, -g)
    P = np.stack([xx.ravel(), yy.ravel(), np.zeros(xx.size)], axis=1)
    nr, nphi = 32, 64
    r = rad * np.sqrt((np.arange(nr) + 0.5) / nr)
    phi = 2 * math.pi * (np.arange(nphi) + 0.5) / nphi
    rr, pp = np.meshgrid(r, phi)
    X = np.stack([rr.ravel() * np.cos(pp.ravel()), rr.ravel() * np.sin(pp.ravel()), np.zeros(rr.size)], axis=1)
    Xw = X @ M[:3, :3].T + M[:3, 3]
    area = math.pi * rad * rad
    E = np.zeros(len(P))
    for k in range(0, len(P), 256):
        v = P[k:k + 256, None, :] - Xw[None, :, :]  # from the disk to P
        dist = np.linalg.norm(v, axis=2)
        w = v / dist[..., None]
        wl = (w.reshape(-1, 3) @ M[:3, :3])  # rigid: R⁻¹ = Rᵀ
        i = d.intensity(wl).reshape(dist.shape)
        cos_p = np.maximum(-w[..., 2], 0.0)
        E[k:k + 256] = (i * cos_p / dist**2).mean(axis=1)  # equal-area points: the mean is ∫ … dA / A
    mean = E.reshape(res, sub, res, sub).mean(axis=(1, 3))
    b = 4
    a_pix = (2 * half / res) ** 2

    def blocks(x):
        return x.reshape(res // b, b, res // b, b).sum(axis=(1, 3)) * a_pix

    spp = 64 if integrator == "path" else 512
    renders = [blocks(render_E(mi, floor_scene(mi, lamp, {"type": integrator, "max_depth": 2}, spp, res, half,
                                               seed=100 + s))) for s in range(8)]
    got, se = np.mean(renders, axis=0), np.std(renders, axis=0, ddof=1) / math.sqrt(8)
    want = blocks(mean)
    assert want.max() > 0 and np.all(np.abs(got - want) <= 5.4 * se + 5e-3 * want + 1e-4 * want.max()), (
        f"blocks off: {np.round((got - want) / np.maximum(se, 1e-30), 1)} se; rel {np.round(got / np.maximum(want, 1e-30) - 1, 4)}")
