"""The Dr.Jit port of gonio's map (``gonio.drjit``) and the Mitsuba emitters written on it
(``"gonio"``, ``"gonio_envmap"`` of ``gonio.mitsuba``): docs/MITSUBA.md.

* **Agreement with the library** (``scalar_rgb`` and ``llvm_ad_rgb``): for the same points u, the
  port's directions and pdfs against ``Sampler.sample`` / ``EnvMap.sample`` on float32 arrays (the
  library's float32 map, from the same tables), its pdf and inverse at those directions, the
  diagram's intensity and the image's radiance, on corpus files, the example, two random
  diagrams (a hemisphere and a sphere) and the shared environment maps. Both variants compute in
  float32 with the kernels' operations (``scalar_rgb`` on width-1 arrays of Dr.Jit's scalar
  backend); Dr.Jit's own sin/cos/atan2 are the only difference: directions within 6e-8, the
  sample's pdf within 1e-4 relative (a few in 10⁴ env samples up to 2e-4, where the density is
  steep and the lifted direction's round-off moves it), the pdf at a direction within 1e-4 for
  ≥ 99 % (measured 99.56 %: atan2's ulp moves φ across a steep sector), the radiance's pixel the same but within
  round-off of a pixel edge.
* **The emitters against the library**: ``sample_ray`` / ``eval_direction`` of the luminaire,
  ``sample_direction`` / ``pdf_direction`` / ``eval`` / ``eval_direction`` of the environment,
  with rotated frames.
* **Mitsuba's chi-square harness** on the emitters' sampling through the scene's emitter calls
  (``scene.sample_emitter_direction``, ``scene.sample_emitter_ray``) with Dr.Jit's symbolic calls
  and loops ON (the defaults; asserted), 1 % level, Šidák over the file's harness tests.
* **Rendering**: a diffuse ball on a floor under each shared map, ``gonio_envmap`` against
  Mitsuba's ``envmap`` (same image, same ``to_world``): the image means agree within 5 standard
  errors of 6 seeds plus 0.5 % (Mitsuba puts its rows on the poles, θ = πr/(H − 1), gonio at
  pixel centres, and reads bilinearly), in ``path``; the same for a glossy ball (rough aluminium,
  α = 0.2) on a rough-plastic floor, the image's mean and the ball's (8 seeds); and ``ptracer``
  (``sample_ray``, ``gonio.mitsuba.prepare``) against ``path``.

Skipped visibly without Mitsuba, the variant (libLLVM), the corpus or the shared maps.
"""

import math
import os
from pathlib import Path

import numpy as np
import pytest

import gonio
from conftest import SUMMARY, corpus_dir
from test_mitsuba_chi2 import converged_chi2

ROOT = Path(__file__).resolve().parents[3]
ENVMAPS = Path(os.environ.get("GONIO_ENVMAPS") or ROOT.parent / "shared" / "data" / "envmaps")
SHARED = sorted(ENVMAPS.glob("*.hdr")) if ENVMAPS.is_dir() else []
FILES = ["ies/lm63_2002_lithonia_wallwash_h90_270.ies", "ldt/isym0_ledil_strada_72x181.ldt",
         "ies/lm63_2002_lithonia_indx_spot_0p5deg.ies", "ies/lm63_1995_qssi_roadway_irregular_grid.ies"]
VARIANTS = ["scalar_rgb", "llvm_ad_rgb"]
N = {"scalar_rgb": 256, "llvm_ad_rgb": 20000}

# Bounds (measured maxima in the comments, both variants, this file's seeds).
DIR_TOL = 1e-5  # max |Δ| of a direction's components (measured ≤ 6e-8)
PDF_TOL = 1e-4  # relative, of the sample's pdf (measured ≤ 2.1e-4 on 3 of 60 000 env samples, else < 1e-4)


def _mitsuba(variant):
    try:
        import mitsuba as mi
    except Exception as e:
        pytest.skip(f"SKIPPED: Mitsuba 3 is not installed ({e}); pip install mitsuba")
    try:
        mi.set_variant(variant)
    except Exception as e:
        pytest.skip(f"SKIPPED: Mitsuba's {variant} variant cannot start (libLLVM? DRJIT_LIBLLVM_PATH): {e}")
    import gonio.mitsuba as gm

    gm.register()
    return mi


@pytest.fixture(params=VARIANTS)
def mi(request):
    return _mitsuba(request.param)


@pytest.fixture
def mi_llvm():
    return _mitsuba("llvm_ad_rgb")


def _scalar(mi):
    return mi.variant().startswith("scalar")


def _corpus(rel):
    c = corpus_dir()
    if c is None or not (c / rel).is_file():
        pytest.skip(f"SKIPPED: corpus file {rel} not found (set GONIO_CORPUS)")
    return c / rel


def _envmap(name):
    p = ENVMAPS / name
    if not p.is_file():
        pytest.skip(f"SKIPPED: shared envmap {name} not found (GONIO_ENVMAPS)")
    return p


def random_diagram(seed, hemisphere):
    from test_mitsuba_chi2 import random_diagram as rd

    return rd(np.random.default_rng(seed), hemisphere)


def _source(name):
    """(kind, library object, blob, diagram or None) for a source name."""
    if name == "example":
        d = gonio.example()
    elif name.startswith("random"):
        d = random_diagram(1000 + int(name[-1]), hemisphere=name.endswith("0"))
    elif name.endswith(".hdr"):
        look = "bilinear" if "bilinear" in name else "nearest"
        env = gonio.EnvMap(_envmap(name.split(":")[-1]), lookup=look, precision="float32")
        return "env", env, env.tables(precision="float32"), None
    else:
        d = gonio.read(_corpus(name))
    s = d.sampler("hds", None if name.startswith("random") else "sphere")
    return "grid", s, s.tables(precision="float32"), d


# Split-layout variety: the upper map only, the lower map only with one meridian, both maps on
# non-uniform meridians.
MORE_FILES = ["ies/lm63_1995_erco_trion_washlight_uplight.ies", "ies/iesna91_amd_rpr_near_duplicate_angles.ies",
              "ies/lm63_2002_rab_wallpack_fine_irregular.ies"]
SOURCES = ["example", "random0", "random1", *FILES, *MORE_FILES, "studio.hdr", "sunset.hdr", "night.hdr",
           "bilinear:studio.hdr"]


def _cols(v, k=3):
    return np.stack([np.asarray(v[c], dtype=np.float64).reshape(-1) for c in range(k)], axis=1)


def _run(mi, T, u, what):
    """Runs the port on points u (n, 2): (directions, pdf, pdf at them, inverse, target/radiance)."""
    if not _scalar(mi):
        f = mi.Float
        d, p = T.sample(mi.Point2f(f(u[:, 0]), f(u[:, 1])))
        q = T.pdf(d)
        iu = T.invert(d)
        t = T.target(d) if what == "grid" else T.radiance(d)
        tv = np.asarray(t, dtype=np.float64).reshape(-1) if what == "grid" else _cols(t)
        return _cols(d), np.asarray(p, np.float64), np.asarray(q, np.float64), _cols(iu, 2), tv
    D, P, Q, U, V = [], [], [], [], []
    for a, b in u:
        d, p = T.sample(mi.Point2f(float(a), float(b)))
        D.append([d.x, d.y, d.z])
        P.append(p)
        Q.append(T.pdf(d))
        iu = T.invert(d)
        U.append([iu.x, iu.y])
        if what == "grid":
            V.append(T.target(d))
        else:
            r = T.radiance(d)
            V.append([r[0], r[1], r[2]])
    return tuple(np.asarray(a, dtype=np.float64) for a in (D, P, Q, U, V))


@pytest.mark.parametrize("name", SOURCES)
def test_port_agrees_with_the_library(mi, name):
    import gonio.drjit as gdr

    kind, lib, blob, diagram = _source(name)
    T = gdr.Tables(blob, mi)
    n = N[mi.variant()]
    u = np.random.default_rng(17).random((n, 2)).astype(np.float32)
    if kind == "env":
        rd, rp, _ = lib.sample(u)
    else:
        rd, rp = lib.sample(u)
    assert rd.dtype == np.float32  # the library's float32 map
    D, P, Q, U, V = _run(mi, T, u, kind)
    derr = np.abs(D - rd).max(axis=1)
    perr = np.abs(P / rp - 1.0)
    # The library's pdf at the same (float32) directions, and the port's pdf there.
    lp = lib.pdf(D.astype(np.float32))
    qerr = np.abs(Q / np.where(lp > 0, lp, 1.0) - 1.0)
    uerr = np.abs(U - u).max(axis=1)
    line = (f"{mi.variant()} {name}: dir max {derr.max():.2g}, sample pdf rel max {perr.max():.2g}, "
            f"pdf(d) rel max {qerr.max():.2g}, invert max {uerr.max():.2g}")
    if kind == "grid":
        lv = diagram.intensity(D)
        verr = np.abs(V - lv) / lv.max()
        line += f", intensity max {verr.max():.2g} of the peak"
        assert verr.max() <= 1e-4, line
    else:
        lv = lib.eval(D)
        if lib.lookup == "nearest":
            # A direction within round-off of a pixel edge may read the neighbour (f32 angles).
            mism = np.any(V != lv, axis=1)
            line += f", {mism.sum()} of {n} pixels read differently"
            assert mism.mean() <= 1e-3, line
        else:
            verr = np.abs(V - lv).max(axis=1) / np.maximum(np.abs(lv).max(axis=1), 1e-6)
            line += f", bilinear radiance rel max {verr.max():.2g}"
            assert np.quantile(verr, 0.99) <= 5e-4 and verr.max() <= 5e-3, line
    SUMMARY.append(line)
    print(line)
    assert derr.max() <= DIR_TOL, line
    assert np.mean(perr <= PDF_TOL) >= 0.9995 and perr.max() <= 1e-3, line
    assert np.mean(qerr <= 1e-4) >= 0.99 and qerr.max() <= 3e-3, line
    assert np.quantile(uerr, 0.99) <= 1e-5 and uerr.max() <= 1e-3, line


def _rot(mi):
    T = mi.ScalarTransform4f
    return T().translate([0.4, -0.3, 2.0]) @ T().rotate([0, 0, 1], 70) @ T().rotate([math.sqrt(0.5), 0.0, math.sqrt(0.5)], 35)


def test_luminaire_emitter_agrees_with_the_library(mi):
    """``sample_ray`` of the point luminaire: the ray's direction is the library's sample turned
    by ``to_world``, its weight scale·I/pdf; ``eval_direction`` toward points is scale·I/r²."""
    path = _corpus(FILES[1])
    d = gonio.read(path)
    s = d.sampler("hds", "sphere")
    Tw = _rot(mi)
    M = np.array(Tw.matrix, dtype=np.float64)
    scene = mi.load_dict({"type": "scene", "lamp": {"type": "gonio", "filename": str(path), "to_world": Tw,
                                                    "scale": 2.0}})
    em = scene.emitters()[0]
    n = 64 if _scalar(mi) else 4096
    u = np.random.default_rng(3).random((n, 2)).astype(np.float32)
    ld, lp = s.sample(u)
    want_d = ld.astype(np.float64) @ M[:3, :3].T
    want_w = 2.0 * d.intensity(ld.astype(np.float64)) / lp
    if _scalar(mi):
        got_d, got_w = [], []
        for a, b in u:
            ray, w = em.sample_ray(0.0, 0.5, mi.Point2f(0.5, 0.5), mi.Point2f(float(a), float(b)))
            got_d.append([ray.d.x, ray.d.y, ray.d.z])
            got_w.append(w[0])
        got_d, got_w = np.array(got_d), np.array(got_w)
    else:
        f = mi.Float
        ray, w = em.sample_ray(f(0.0), f(0.5), mi.Point2f(0.5, 0.5), mi.Point2f(f(u[:, 0]), f(u[:, 1])))
        got_d, got_w = _cols(ray.d), np.asarray(w[0], dtype=np.float64)
    assert np.abs(got_d - want_d).max() <= 1e-5
    assert np.allclose(got_w, want_w, rtol=2e-4, atol=1e-6 * want_w.max())
    # eval_direction from points around the luminaire.
    rng = np.random.default_rng(4)
    m = 32 if _scalar(mi) else 2048
    p = M[:3, 3] + rng.normal(size=(m, 3)) * 2.0
    v = M[:3, 3] - p
    r = np.linalg.norm(v, axis=1)
    loc = (-v / r[:, None]) @ np.linalg.inv(M[:3, :3]).T
    want = 2.0 * d.intensity(loc) / r**2
    it = mi.Interaction3f()
    if _scalar(mi):
        got = []
        for k in range(m):
            it.p = mi.Point3f(*p[k])
            ds, _ = em.sample_direction(it, mi.Point2f(0.5, 0.5))
            assert abs(ds.dist - r[k]) <= 1e-5 * r[k]
            got.append(em.eval_direction(it, ds)[0])
        got = np.array(got)
    else:
        f = mi.Float
        it.p = mi.Point3f(f(p[:, 0]), f(p[:, 1]), f(p[:, 2]))
        ds, w = em.sample_direction(it, mi.Point2f(f(np.full(m, 0.5)), f(np.full(m, 0.5))))
        got = np.asarray(em.eval_direction(it, ds)[0], dtype=np.float64)
        assert np.allclose(np.asarray(w[0]), got, rtol=1e-5, atol=1e-7 * got.max())
    assert np.allclose(got, want, rtol=2e-4, atol=1e-5 * want.max())


@pytest.mark.parametrize("name", ["studio.hdr", "night.hdr"])
def test_envmap_emitter_agrees_with_the_library(mi, name):
    """``gonio_envmap`` under a rotated ``to_world``: ``sample_direction`` gives the library's
    sample (gonio (x, y, z) = Mitsuba local (y, z, x), then ``to_world``), its exact pdf and
    weight radiance/pdf; ``pdf_direction``, ``eval`` (escaped rays) and ``eval_direction`` repeat
    the library at those directions."""
    path = _envmap(name)
    env = gonio.EnvMap(path, precision="float32")
    T = mi.ScalarTransform4f
    Tw = T().rotate([0, 0, 1], 30) @ T().rotate([1, 0, 0], 90)
    M = np.array(Tw.matrix, dtype=np.float64)[:3, :3] @ np.array([[0, 1, 0], [0, 0, 1], [1, 0, 0]], dtype=np.float64)
    scene = mi.load_dict({"type": "scene", "env": {"type": "gonio_envmap", "filename": str(path), "to_world": Tw,
                                                   "scale": 1.5}})
    em = scene.emitters()[0]
    assert em.is_environment()
    n = 48 if _scalar(mi) else 8192
    u = np.random.default_rng(8).random((n, 2)).astype(np.float32)
    gd, gp, grgb = env.sample(u)
    want_d = gd.astype(np.float64) @ M.T
    it = mi.Interaction3f()
    if _scalar(mi):
        D, P, W, Q, E, ED = [], [], [], [], [], []
        it.p = mi.Point3f(0.1, 0.2, 0.3)
        for a, b in u:
            ds, w = em.sample_direction(it, mi.Point2f(float(a), float(b)))
            D.append([ds.d.x, ds.d.y, ds.d.z])
            P.append(ds.pdf)
            W.append([w[0], w[1], w[2]])
            Q.append(em.pdf_direction(it, ds))
            si = mi.SurfaceInteraction3f()
            si.wi = -ds.d
            e = em.eval(si)
            E.append([e[0], e[1], e[2]])
            e = em.eval_direction(it, ds)
            ED.append([e[0], e[1], e[2]])
        D, P, W, Q, E, ED = map(np.array, (D, P, W, Q, E, ED))
    else:
        f = mi.Float
        it.p = mi.Point3f(f(np.full(n, 0.1)), f(np.full(n, 0.2)), f(np.full(n, 0.3)))
        ds, w = em.sample_direction(it, mi.Point2f(f(u[:, 0]), f(u[:, 1])))
        D, P, W = _cols(ds.d), np.asarray(ds.pdf, np.float64), _cols(w)
        Q = np.asarray(em.pdf_direction(it, ds), np.float64)
        si = dr_zeros_si(mi, n)
        si.wi = -ds.d
        E = _cols(em.eval(si))
        ED = _cols(em.eval_direction(it, ds))
    assert np.abs(D - want_d).max() <= 1e-5
    ok = np.abs(P / gp - 1.0) <= 1e-4
    assert ok.mean() >= 0.999
    want_w = 1.5 * grgb / gp[:, None]
    # The same pixel but where the direction lies within round-off of a pixel edge.
    close = np.all(np.abs(W - want_w) <= 2e-4 * np.abs(want_w) + 1e-6 * want_w.max(), axis=1)
    assert close[ok].mean() >= 0.995
    assert np.allclose(Q, P, rtol=2e-3)
    same = np.all(E == 1.5 * grgb.astype(np.float32), axis=1) | np.all(np.abs(E - 1.5 * grgb) <= 1e-6 * np.abs(grgb).max(), axis=1)
    assert same.mean() >= 0.99
    assert np.array_equal(E, ED)


def dr_zeros_si(mi, n):
    import drjit as dr

    return dr.zeros(mi.SurfaceInteraction3f, n)


# ---------------------------------------------------------------------------------------------
# Mitsuba's chi-square harness, through the scene's emitter calls, symbolic calls and loops ON.
# ---------------------------------------------------------------------------------------------

CHI2_CASES = ["gonio:" + FILES[0], "gonio:" + FILES[1], "gonio:random1"] + [
    "gonio_envmap:" + n for n in ("studio.hdr", "sunset.hdr", "night.hdr")]
CHI2_SAMPLES = 1_000_000


@pytest.mark.parametrize("case", CHI2_CASES)
def test_mitsuba_chi2_on_the_emitters(mi_llvm, case):
    import drjit as dr
    from mitsuba import chi2

    mi = mi_llvm
    # The point of this test: the emitters run inside symbolic calls and loops (Mitsuba's defaults).
    assert dr.flag(dr.JitFlag.SymbolicCalls) and dr.flag(dr.JitFlag.SymbolicLoops)
    kind, src = case.split(":", 1)
    f = mi.Float
    if kind == "gonio_envmap":
        scene = mi.load_dict({"type": "scene", "env": {"type": "gonio_envmap", "filename": str(_envmap(src))}})
        em = scene.emitters()[0]
        ptr = mi.EmitterPtr(em)

        def sample_func(sample):
            it = dr.zeros(mi.Interaction3f, dr.width(sample))
            ds, _ = scene.sample_emitter_direction(it, sample, False)
            return ds.d

        def pdf_func(wo):
            it = dr.zeros(mi.Interaction3f, dr.width(wo))
            ds = dr.zeros(mi.DirectionSample3f, dr.width(wo))
            ds.d, ds.emitter = wo, ptr
            return scene.pdf_emitter_direction(it, ds)
    else:
        if src.startswith("random"):
            path = Path(os.environ.get("TMPDIR", "/tmp")) / f"gonio-chi2-{os.getpid()}-{src}.json"
            path.write_text(random_diagram(1000 + int(src[-1]), hemisphere=False).to_json())
        else:
            path = _corpus(src)
        scene = mi.load_dict({"type": "scene", "lamp": {"type": "gonio", "filename": str(path)}})
        em = scene.emitters()[0]

        def sample_func(sample):
            n = dr.width(sample)
            ray, _, _ = scene.sample_emitter_ray(f(0.0), dr.zeros(f, n), mi.Point2f(0.5, 0.5), sample, True)
            return ray.d

        def pdf_func(wo):
            return em.tables.pdf(wo)  # identity to_world: world = local

    ok, ires, p, messages = converged_chi2(chi2, sample_func, pdf_func, seed=41,
                                           test_count=len(CHI2_CASES), sample_count=CHI2_SAMPLES)
    SUMMARY.append(f"{'accepted' if ok else 'REJECTED'}  p = {p:.4f}  ires = {ires:2d}  {case} (Dr.Jit emitter, symbolic)")
    assert ok, messages


# ---------------------------------------------------------------------------------------------
# Rendering against Mitsuba's envmap.
# ---------------------------------------------------------------------------------------------


EYE = [0, -5, 1.5]  # the camera of the ball scenes, looking at the ball's centre (the origin)
FOV = 40


def _ball_scene(mi, kind, path, integrator, spp=32, res=48, lookup=None, glossy=False):
    """A unit ball on a floor under the map. Diffuse: a diffuse ball (0.7) on a diffuse floor.
    Glossy: a rough aluminium ball (``roughconductor``, GGX α = 0.2) on a ``roughplastic`` floor
    (α = 0.15, diffuse 0.5)."""
    T = mi.ScalarTransform4f
    em = {"type": kind, "filename": str(path), "to_world": T().rotate([0, 0, 1], 30) @ T().rotate([1, 0, 0], 90)}
    if lookup:
        em["lookup"] = lookup
    if glossy:
        ball = {"type": "roughconductor", "material": "Al", "distribution": "ggx", "alpha": 0.2}
        floor = {"type": "roughplastic", "distribution": "ggx", "alpha": 0.15,
                 "diffuse_reflectance": {"type": "rgb", "value": [0.5] * 3}}
    else:
        ball = {"type": "diffuse", "reflectance": {"type": "rgb", "value": [0.7] * 3}}
        floor = {"type": "diffuse"}
    import gonio.mitsuba as gm

    return gm.prepare(mi.load_dict({
        "type": "scene", "integrator": {"type": integrator, "max_depth": 3},
        "sensor": {"type": "perspective", "fov": FOV,
                   "to_world": T().look_at(origin=EYE, target=[0, 0, 0], up=[0, 0, 1]),
                   "film": {"type": "hdrfilm", "width": res, "height": res, "rfilter": {"type": "box"}},
                   "sampler": {"type": "independent", "sample_count": spp}},
        "ball": {"type": "sphere", "bsdf": ball},
        "floor": {"type": "rectangle", "to_world": T().translate([0, 0, -1]) @ T().scale(3), "bsdf": floor},
        "env": em,
    }))


def _ball_mask(res):
    """Pixels whose centre lies within 0.9 of the ball's projected radius (the ball is centred in
    the picture): every one of them sees the ball."""
    x = (np.arange(res) + 0.5) / res * 2.0 - 1.0
    r_edge = math.tan(math.asin(1.0 / float(np.linalg.norm(EYE)))) / math.tan(math.radians(FOV / 2))
    return np.hypot(*np.meshgrid(x, x)) < 0.9 * r_edge


def _means(mi, scene, seeds=6):
    return np.array([np.array(mi.render(scene, seed=k), dtype=np.float64).mean(axis=(0, 1)) for k in range(seeds)])


@pytest.mark.parametrize("name", [p.name for p in SHARED] or ["studio.hdr"])
def test_render_matches_mitsuba_envmap(mi_llvm, name):
    mi = mi_llvm
    path = _envmap(name)
    a = _means(mi, _ball_scene(mi, "envmap", path, "path"))
    b = _means(mi, _ball_scene(mi, "gonio_envmap", path, "path", lookup="bilinear"))
    se = np.sqrt(a.var(0, ddof=1) / len(a) + b.var(0, ddof=1) / len(b))
    diff = b.mean(0) - a.mean(0)
    line = f"render {name}: gonio_envmap / envmap − 1 = {np.round(b.mean(0) / a.mean(0) - 1, 4)}, z = {np.round(diff / se, 2)}"
    SUMMARY.append(line)
    assert np.all(np.abs(diff) <= 5.0 * se + 5e-3 * a.mean(0)), line


@pytest.mark.parametrize("name", [p.name for p in SHARED] or ["studio.hdr"])
def test_glossy_render_matches_mitsuba_envmap(mi_llvm, name):
    """A glossy ball (rough aluminium, α = 0.2) on a glossy floor (rough plastic), ``path`` with
    MIS (next-event estimation through ``sample_direction``/``pdf_direction``, BSDF rays through
    ``eval``): ``gonio_envmap`` against Mitsuba's ``envmap``, the mean of the whole image and of
    the pixels that see the ball (its highlights: the reflected lights), 8 seeds of 64 spp at
    48 × 48 each, within 5 standard errors + 0.5 %. The ball's mean is heavy-tailed under
    studio.hdr (a few pixels reflect its small, bright lights; measured |z| ≤ 3.4 over 16
    groups of 8 seeds, no bias beyond 0.5 % in their mean), hence the unpaired standard error
    from the seeds' spread, as the diffuse test."""
    mi = mi_llvm
    path = _envmap(name)
    res, seeds = 48, 8
    mask = _ball_mask(res)
    out = {}
    for kind, lookup in (("envmap", None), ("gonio_envmap", "bilinear")):
        scene = _ball_scene(mi, kind, path, "path", spp=64, res=res, lookup=lookup, glossy=True)
        imgs = [np.array(mi.render(scene, seed=k), dtype=np.float64) for k in range(seeds)]
        out[kind] = {"image": np.array([i.mean(axis=(0, 1)) for i in imgs]),
                     "ball": np.array([i[mask].mean(axis=0) for i in imgs])}
    for part in ("image", "ball"):
        a, b = out["envmap"][part], out["gonio_envmap"][part]
        se = np.sqrt(a.var(0, ddof=1) / len(a) + b.var(0, ddof=1) / len(b))
        diff = b.mean(0) - a.mean(0)
        line = (f"glossy {name} {part}: gonio_envmap / envmap − 1 = {np.round(b.mean(0) / a.mean(0) - 1, 4)}, "
                f"z = {np.round(diff / se, 2)}")
        SUMMARY.append(line)
        assert np.all(np.abs(diff) <= 5.0 * se + 5e-3 * a.mean(0)), line


def test_ptracer_matches_path_under_gonio_envmap(mi_llvm):
    """Light tracing (``sample_ray`` from the bounding sphere that ``prepare`` set) renders the
    same image mean as path tracing."""
    mi = mi_llvm
    path = _envmap("sunset.hdr")
    a = _means(mi, _ball_scene(mi, "gonio_envmap", path, "path"))
    b = _means(mi, _ball_scene(mi, "gonio_envmap", path, "ptracer"))
    se = np.sqrt(a.var(0, ddof=1) / len(a) + b.var(0, ddof=1) / len(b))
    diff = b.mean(0) - a.mean(0)
    assert np.all(np.abs(diff) <= 5.0 * se + 5e-3 * a.mean(0)), f"ptracer/path − 1 = {b.mean(0) / a.mean(0) - 1}, z = {diff / se}"


def test_register_leaves_the_jit_flags_alone(mi_llvm):
    import drjit as dr

    import gonio.mitsuba as gm

    before = [dr.flag(f) for f in (dr.JitFlag.SymbolicCalls, dr.JitFlag.SymbolicLoops)]
    gm.register(jit_flags=True)
    assert [dr.flag(f) for f in (dr.JitFlag.SymbolicCalls, dr.JitFlag.SymbolicLoops)] == before


def test_envmap_options_and_the_xml_form(mi_llvm, tmp_path):
    """``weight``, ``lookup`` and ``mis_compensation`` reach the map (the emitter's pdf and radiance
    are the library's ``EnvMap`` with the same options), loaded from XML."""
    mi = mi_llvm
    path = _envmap("night.hdr")
    scene = mi.load_string(f"""<scene version="3.0.0">
        <emitter type="gonio_envmap">
            <string name="filename" value="{path}"/>
            <string name="weight" value="green"/>
            <string name="lookup" value="bilinear"/>
            <boolean name="mis_compensation" value="true"/>
            <float name="scale" value="0.5"/>
        </emitter>
        <emitter type="gonio">
            <string name="filename" value="{_corpus(FILES[0])}"/>
            <transform name="to_world"><translate z="8"/></transform>
        </emitter>
    </scene>""")
    env = gonio.EnvMap(path, weight="green", lookup="bilinear", mis_compensation=True, precision="float32")
    em = [e for e in scene.emitters() if getattr(e, "is_gonio_envmap", False)][0]
    n = 4096
    u = np.random.default_rng(9).random((n, 2)).astype(np.float32)
    gd, gp, grgb = env.sample(u)
    f = mi.Float
    it = dr_zeros_si(mi, n)
    ds, w = em.sample_direction(it, mi.Point2f(f(u[:, 0]), f(u[:, 1])))
    # identity to_world: Mitsuba local (y, z, x) = gonio (x, y, z)
    d = _cols(ds.d)
    assert np.abs(d[:, [2, 0, 1]] - gd).max() <= 1e-5
    p = np.asarray(ds.pdf, np.float64)
    assert np.mean(np.abs(p / gp - 1) <= 1e-4) >= 0.999
    si = dr_zeros_si(mi, n)
    si.wi = -ds.d
    e = _cols(em.eval(si))
    close = np.all(np.abs(e - 0.5 * grgb) <= 5e-4 * np.abs(grgb).max(axis=1, keepdims=True) + 1e-7, axis=1)
    assert close.mean() >= 0.99
