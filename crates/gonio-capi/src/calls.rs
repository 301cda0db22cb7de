//! Single calls: the diagram getters, building samplers, and one point at a time (sample, pdf,
//! target pdf, invert, ratio bound, target power).

use super::*;
use gonio::mapping::SphereLayout;
use gonio::sampler::Vec3;
use gonio::{BuildOptions, Method};
use gonio::{Domain, InvertError};
use std::ffi::c_char;
use std::panic::{catch_unwind, AssertUnwindSafe};

/// The total power of the distribution: the integral over the sphere of the intensity
/// interpolated bilinearly in (θ, φ), in lumens for photometric files (the `flux` of
/// `gonio info`).
///
/// # Safety
/// `diagram` must be NULL or a live handle; `flux` NULL or valid for writing a double.
#[no_mangle]
pub unsafe extern "C" fn gonio_diagram_flux(
    diagram: *const GonioDiagram,
    flux: *mut f64,
) -> GonioStatus {
    guard(|| {
        let d = r(diagram, "diagram")?;
        w(flux, d.diagram.integral(), "flux")
    })
}

/// The largest intensity of the distribution (candela for photometric files).
///
/// # Safety
/// `diagram` must be NULL or a live handle; `max` NULL or valid for writing a double.
#[no_mangle]
pub unsafe extern "C" fn gonio_diagram_max_intensity(
    diagram: *const GonioDiagram,
    max: *mut f64,
) -> GonioStatus {
    guard(|| {
        let d = r(diagram, "diagram")?;
        w(max, d.diagram.max_value(), "max")
    })
}

/// The intensity of the distribution in a direction (candela for photometric files), interpolated
/// bilinearly in (θ, φ) — the function every sampler's target density is proportional to.
///
/// # Safety
/// `diagram` must be NULL or a live handle; `intensity` NULL or valid for writing a double.
#[no_mangle]
pub unsafe extern "C" fn gonio_diagram_intensity(
    diagram: *const GonioDiagram,
    x: f64,
    y: f64,
    z: f64,
    intensity: *mut f64,
) -> GonioStatus {
    guard(|| {
        let d = r(diagram, "diagram")?;
        check_out(intensity, "intensity")?;
        let dir = unit([x, y, z])?;
        let (theta, phi) = gonio::sampler::spherical(dir);
        w(intensity, d.diagram.interpolate(theta, phi), "intensity")
    })
}

/// The number of warnings the reader issued (0 for JSON diagrams).
///
/// # Safety
/// `diagram` must be NULL or a live handle; `count` NULL or valid for writing a `size_t`.
#[no_mangle]
pub unsafe extern "C" fn gonio_diagram_warning_count(
    diagram: *const GonioDiagram,
    count: *mut usize,
) -> GonioStatus {
    guard(|| {
        let d = r(diagram, "diagram")?;
        w(count, d.warnings.len(), "count")
    })
}

/// Warning number `index` (from 0) as the CLI prints it: `FILE:LINE:COLUMN: warning: message`.
/// The string belongs to the diagram handle and lives as long as it.
///
/// # Safety
/// `diagram` must be NULL or a live handle; `text` NULL or valid for writing a pointer.
#[no_mangle]
pub unsafe extern "C" fn gonio_diagram_warning(
    diagram: *const GonioDiagram,
    index: usize,
    text: *mut *const c_char,
) -> GonioStatus {
    guard(|| {
        let d = r(diagram, "diagram")?;
        write_warning(&d.warnings, index, "diagram", text)
    })
}

/// The domain [`GONIO_DOMAIN_AUTO`] stands for with this diagram ([`GONIO_DOMAIN_HEMISPHERE`] or
/// [`GONIO_DOMAIN_SPHERE`]).
///
/// # Safety
/// `diagram` must be NULL or a live handle; `domain` NULL or valid for writing an `int32_t`.
#[no_mangle]
pub unsafe extern "C" fn gonio_diagram_domain(
    diagram: *const GonioDiagram,
    domain: *mut GonioDomain,
) -> GonioStatus {
    guard(|| {
        let d = r(diagram, "diagram")?;
        w(domain, domain_code(auto_domain(d)), "domain")
    })
}

// ---------------------------------------------------------------------------------------------
// Building.

/// The CLI's policy: photometric files always get the sphere, a JSON diagram
/// [`Domain::for_diagram`].
pub(crate) fn auto_domain(d: &GonioDiagram) -> Domain {
    if d.photometry.is_some() {
        Domain::Sphere
    } else {
        Domain::for_diagram(&d.diagram)
    }
}

pub(crate) fn domain_code(d: Domain) -> GonioDomain {
    match d {
        Domain::Hemisphere => GONIO_DOMAIN_HEMISPHERE,
        Domain::Sphere => GONIO_DOMAIN_SPHERE,
    }
}

pub(crate) fn method_of(method: GonioMethod) -> Result<Method, Failure> {
    match method {
        GONIO_METHOD_HDS => Ok(Method::Hds),
        GONIO_METHOD_PIECEWISE_CONSTANT => Ok(Method::PiecewiseConstant),
        GONIO_METHOD_BILINEAR => Ok(Method::Bilinear),
        GONIO_METHOD_REJECTION => Ok(Method::Rejection),
        GONIO_METHOD_UNIFORM => Ok(Method::Uniform),
        other => Err(Failure::invalid(format!(
            "unknown method {other}; expected one of the GONIO_METHOD_* constants (0 to 4)"
        ))),
    }
}

pub(crate) fn domain_of(d: &GonioDiagram, domain: GonioDomain) -> Result<Domain, Failure> {
    match domain {
        GONIO_DOMAIN_AUTO => Ok(auto_domain(d)),
        GONIO_DOMAIN_HEMISPHERE => Ok(Domain::Hemisphere),
        GONIO_DOMAIN_SPHERE => Ok(Domain::Sphere),
        other => Err(Failure::invalid(format!(
            "unknown domain {other}; expected GONIO_DOMAIN_AUTO, _HEMISPHERE or _SPHERE"
        ))),
    }
}

pub(crate) fn options_of(o: &GonioBuildOptions) -> Result<BuildOptions, Failure> {
    let mut b = BuildOptions::default();
    if o.tolerance != 0.0 {
        b = b.tolerance(Some(o.tolerance));
    }
    if o.resolution != 0 {
        b = b.resolution(o.resolution);
    }
    b = b.seed(o.seed);
    b = b.sphere_layout(match o.sphere_layout {
        GONIO_SPHERE_LAYOUT_SPLIT => SphereLayout::Split,
        GONIO_SPHERE_LAYOUT_LAMBERT => SphereLayout::Lambert,
        other => {
            return Err(Failure::invalid(format!(
                "unknown sphere layout {other}; expected GONIO_SPHERE_LAYOUT_SPLIT or _LAMBERT"
            )))
        }
    });
    Ok(b)
}

/// Builds through the library's factory, with the CLI's message on failure.
pub(crate) fn build(
    diagram: *const GonioDiagram,
    method: GonioMethod,
    domain: GonioDomain,
    options: &BuildOptions,
    out: *mut *mut GonioSampler,
) -> Result<(), Failure> {
    check_out(out, "out")?;
    // SAFETY: the caller passes NULL or a live handle (the exported functions' contract).
    let d = unsafe { r(diagram, "diagram")? };
    let m = method_of(method)?;
    let dom = domain_of(d, domain)?;
    let s = m.build_with(&d.diagram, dom, options).map_err(|e| {
        Failure::new(
            GONIO_ERR_BUILD,
            format!("{}: cannot build the {m} sampler: {e}", d.name),
        )
    })?;
    // SAFETY: `out` was checked above.
    unsafe {
        w(
            out,
            Box::into_raw(Box::new(GonioSampler { inner: s })),
            "out",
        )
    }
}

/// Builds a sampler of `method` (a `GONIO_METHOD_*` constant) on `domain` (a `GONIO_DOMAIN_*`
/// constant; [`GONIO_DOMAIN_AUTO`] for the diagram's own policy) with default options, through
/// the library's factory `Method::build`. On success `*out` receives a new handle that the caller
/// releases with [`gonio_sampler_free`]; it does not borrow `diagram`.
///
/// # Safety
/// `diagram` must be NULL or a live handle; `out` NULL or valid for writing a pointer.
#[no_mangle]
pub unsafe extern "C" fn gonio_sampler_build(
    diagram: *const GonioDiagram,
    method: GonioMethod,
    domain: GonioDomain,
    out: *mut *mut GonioSampler,
) -> GonioStatus {
    guard(|| build(diagram, method, domain, &BuildOptions::default(), out))
}

/// Writes the default options into `*options`.
///
/// # Safety
/// `options` must be NULL or valid for writing a [`GonioBuildOptions`].
#[no_mangle]
pub unsafe extern "C" fn gonio_build_options_default(
    options: *mut GonioBuildOptions,
) -> GonioStatus {
    guard(|| {
        let d = BuildOptions::default();
        let layout = match d.sphere_layout {
            SphereLayout::Lambert => GONIO_SPHERE_LAYOUT_LAMBERT,
            _ => GONIO_SPHERE_LAYOUT_SPLIT,
        };
        w(
            options,
            GonioBuildOptions {
                tolerance: d.tolerance.unwrap_or(0.0),
                resolution: 0,
                seed: d.seed,
                sphere_layout: layout,
            },
            "options",
        )
    })
}

/// As [`gonio_sampler_build`] with `options` (through the factory's `Method::build_with`).
///
/// # Safety
/// `diagram` must be NULL or a live handle; `options` NULL or a valid [`GonioBuildOptions`];
/// `out` NULL or valid for writing a pointer.
#[no_mangle]
pub unsafe extern "C" fn gonio_sampler_build_with(
    diagram: *const GonioDiagram,
    method: GonioMethod,
    domain: GonioDomain,
    options: *const GonioBuildOptions,
    out: *mut *mut GonioSampler,
) -> GonioStatus {
    guard(|| {
        let o = options_of(r(options, "options")?)?;
        build(diagram, method, domain, &o, out)
    })
}

/// Releases a sampler handle. NULL is accepted and ignored.
///
/// # Safety
/// `sampler` must be NULL or a handle from [`gonio_sampler_build`] that was not freed yet, and no
/// other thread may be using it.
#[no_mangle]
pub unsafe extern "C" fn gonio_sampler_free(sampler: *mut GonioSampler) {
    if !sampler.is_null() {
        let _ = catch_unwind(AssertUnwindSafe(|| drop(Box::from_raw(sampler))));
    }
}

/// The method's name as the CLI's `--method` spells it (`"hds"`, `"piecewise-constant"`, …): a
/// static string; NULL when `sampler` is NULL.
///
/// # Safety
/// `sampler` must be NULL or a live handle.
#[no_mangle]
pub unsafe extern "C" fn gonio_sampler_method(sampler: *const GonioSampler) -> *const c_char {
    let Ok(s) = r(sampler, "sampler") else {
        return std::ptr::null();
    };
    match catch_unwind(AssertUnwindSafe(|| s.inner.name())) {
        Ok("hds") => c"hds".as_ptr(),
        Ok("piecewise-constant") => c"piecewise-constant".as_ptr(),
        Ok("bilinear") => c"bilinear".as_ptr(),
        Ok("rejection") => c"rejection".as_ptr(),
        Ok("uniform") => c"uniform".as_ptr(),
        _ => c"unknown".as_ptr(),
    }
}

/// The sampler's domain ([`GONIO_DOMAIN_HEMISPHERE`] or [`GONIO_DOMAIN_SPHERE`]).
///
/// # Safety
/// `sampler` must be NULL or a live handle; `domain` NULL or valid for writing an `int32_t`.
#[no_mangle]
pub unsafe extern "C" fn gonio_sampler_domain(
    sampler: *const GonioSampler,
    domain: *mut GonioDomain,
) -> GonioStatus {
    guard(|| {
        let s = r(sampler, "sampler")?;
        w(domain, domain_code(s.inner.domain()), "domain")
    })
}

// ---------------------------------------------------------------------------------------------
// One point.

/// A direction argument as a unit vector, or an error for a zero or non-finite vector.
pub(crate) fn unit(d: Vec3) -> Result<Vec3, Failure> {
    gonio::sampler::normalize(d).ok_or_else(|| {
        Failure::invalid(format!(
            "the direction {} is not a finite non-zero vector",
            fmt_row(&d)
        ))
    })
}

/// Numbers for a message, `(x, y, z)`, in the shortest form that reads back (exponent form for
/// tiny and huge magnitudes).
pub(crate) fn fmt_row(r: &[f64]) -> String {
    let parts: Vec<String> = r.iter().map(|&x| gonio::decimal::shortest(x)).collect();
    format!("({})", parts.join(", "))
}

/// A point argument, which must lie in the unit square [0, 1]² (NaN does not): the rule of the
/// Python package too (issue 25; before, NaN was "clamped" to a direction of pdf 0).
pub(crate) fn in_square(u: [f64; 2]) -> Result<[f64; 2], Failure> {
    if (0.0..=1.0).contains(&u[0]) && (0.0..=1.0).contains(&u[1]) {
        Ok(u)
    } else {
        Err(Failure::invalid(format!(
            "the point {} is outside the unit square [0, 1]² (or NaN)",
            fmt_row(&u)
        )))
    }
}

/// Maps the point (u, v) of the unit square to a direction and its exact density. A point outside
/// [0, 1]² or with a NaN coordinate is [`GONIO_ERR_INVALID_ARGUMENT`] (as in Python).
///
/// # Safety
/// `sampler` must be NULL or a live handle; `out` NULL or valid for writing a [`GonioSample`].
#[no_mangle]
pub unsafe extern "C" fn gonio_sample(
    sampler: *const GonioSampler,
    u: f64,
    v: f64,
    out: *mut GonioSample,
) -> GonioStatus {
    guard(|| {
        let s = r(sampler, "sampler")?;
        check_out(out, "out")?;
        let smp = s.inner.sample(in_square([u, v])?);
        w(
            out,
            GonioSample {
                direction: smp.direction,
                pdf: smp.pdf,
            },
            "out",
        )
    })
}

/// The density of the sampler at direction (x, y, z) (normalised first), per steradian; 0
/// outside the domain. A zero or non-finite vector is [`GONIO_ERR_INVALID_ARGUMENT`].
///
/// # Safety
/// `sampler` must be NULL or a live handle; `pdf` NULL or valid for writing a double.
#[no_mangle]
pub unsafe extern "C" fn gonio_pdf(
    sampler: *const GonioSampler,
    x: f64,
    y: f64,
    z: f64,
    pdf: *mut f64,
) -> GonioStatus {
    guard(|| {
        let s = r(sampler, "sampler")?;
        check_out(pdf, "pdf")?;
        let d = unit([x, y, z])?;
        w(pdf, s.inner.pdf(d), "pdf")
    })
}

/// The target density at direction (x, y, z): the diagram interpolated bilinearly in (θ, φ),
/// normalised over the domain, per steradian.
///
/// # Safety
/// `sampler` must be NULL or a live handle; `target_pdf` NULL or valid for writing a double.
#[no_mangle]
pub unsafe extern "C" fn gonio_target_pdf(
    sampler: *const GonioSampler,
    x: f64,
    y: f64,
    z: f64,
    target_pdf: *mut f64,
) -> GonioStatus {
    guard(|| {
        let s = r(sampler, "sampler")?;
        check_out(target_pdf, "target_pdf")?;
        let d = unit([x, y, z])?;
        w(target_pdf, s.inner.target_pdf(d), "target_pdf")
    })
}

pub(crate) fn invert_error(e: InvertError) -> Failure {
    match e {
        InvertError::Unsupported => Failure::new(GONIO_ERR_UNSUPPORTED, e.to_string()),
        InvertError::OutsideDomain => Failure::new(GONIO_ERR_OUTSIDE_DOMAIN, e.to_string()),
        InvertError::ZeroDensity => Failure::new(GONIO_ERR_ZERO_DENSITY, e.to_string()),
    }
}

/// The point (u, v) of the unit square that the sampler maps to direction (x, y, z).
/// [`GONIO_ERR_UNSUPPORTED`] for a method without inverse, [`GONIO_ERR_OUTSIDE_DOMAIN`] for a
/// direction outside the domain, [`GONIO_ERR_ZERO_DENSITY`] for a direction in the domain where
/// the density is 0 (no point maps to it).
///
/// # Safety
/// `sampler` must be NULL or a live handle; `u` and `v` NULL or valid for writing a double.
#[no_mangle]
pub unsafe extern "C" fn gonio_invert(
    sampler: *const GonioSampler,
    x: f64,
    y: f64,
    z: f64,
    u: *mut f64,
    v: *mut f64,
) -> GonioStatus {
    guard(|| {
        let s = r(sampler, "sampler")?;
        check_out(u, "u")?;
        check_out(v, "v")?;
        let d = unit([x, y, z])?;
        let p = s.inner.invert(d).map_err(invert_error)?;
        w(u, p[0], "u")?;
        w(v, p[1], "v")
    })
}

/// The guaranteed bound `min ≤ pdf / target_pdf ≤ max` of the sampler over its domain where the
/// target is positive. [`GONIO_ERR_UNSUPPORTED`] when the method states none.
///
/// # Safety
/// `sampler` must be NULL or a live handle; `min` and `max` NULL or valid for writing a double.
#[no_mangle]
pub unsafe extern "C" fn gonio_sampler_ratio_bound(
    sampler: *const GonioSampler,
    min: *mut f64,
    max: *mut f64,
) -> GonioStatus {
    guard(|| {
        let s = r(sampler, "sampler")?;
        check_out(min, "min")?;
        check_out(max, "max")?;
        let (lo, hi) = s.inner.ratio_bound().ok_or_else(|| {
            Failure::new(
                GONIO_ERR_UNSUPPORTED,
                format!("the {} sampler states no ratio bound", s.inner.name()),
            )
        })?;
        w(min, lo, "min")?;
        w(max, hi, "max")
    })
}

/// The power of the sampler's target: the integral over its domain of the intensity that
/// `target_pdf` normalises, in lumens for photometric files (candela × sr). For the HDS map it is
/// the power of the diagram as completed for its tables; it equals [`gonio_diagram_flux`] when
/// the completion adds nothing.
///
/// # Safety
/// `sampler` must be NULL or a live handle; `power` NULL or valid for writing a double.
#[no_mangle]
pub unsafe extern "C" fn gonio_sampler_target_power(
    sampler: *const GonioSampler,
    power: *mut f64,
) -> GonioStatus {
    guard(|| {
        let s = r(sampler, "sampler")?;
        w(power, s.inner.target_power(), "power")
    })
}
