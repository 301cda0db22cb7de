//! Analytic BRDFs, the ground truth of the tests and of the files the tests write: Lambert, GGX
//! (isotropic and anisotropic) with height-correlated Smith masking, Ashikhmin–Shirley
//! (anisotropic Phong lobe) and a two-lobe mix (Lambert + GGX). Frame and units as in
//! [`super`]: f_r in 1/sr, directions away from the surface.
//!
//! Cosines are clamped to ≥ 1e-4 inside the formulas, so that table nodes on the horizon (θ = 90°)
//! hold finite values (they are multiplied by cos θ_o = 0 in every slice diagram anyway).

use super::{uniform_phi, uniform_theta, BrdfError, Symmetry, TabulatedBrdf};
use crate::sampler::{direction, Vec3};
use std::f64::consts::PI;

const MIN_COS: f64 = 1e-4;

/// An analytic BRDF.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Analytic {
    /// ρ/π per channel.
    Lambert {
        /// Albedo per channel.
        albedo: [f64; 3],
    },
    /// GGX microfacets: D(h)·G₂(ω_i, ω_o)·F / (4 cos θ_i cos θ_o), constant F per channel.
    Ggx {
        /// Roughness along x.
        alpha_x: f64,
        /// Roughness along y (= `alpha_x` for an isotropic lobe).
        alpha_y: f64,
        /// Fresnel reflectance per channel (constant).
        f0: [f64; 3],
    },
    /// Ashikhmin–Shirley's anisotropic Phong specular lobe with Schlick's Fresnel.
    AshikhminShirley {
        /// Exponent along x.
        nu: f64,
        /// Exponent along y.
        nv: f64,
        /// Specular reflectance at normal incidence per channel.
        rs: [f64; 3],
    },
    /// Lambert (albedo `kd`) plus an isotropic GGX lobe (`alpha`, `f0`).
    Mix {
        /// Diffuse albedo per channel.
        kd: [f64; 3],
        /// GGX roughness.
        alpha: f64,
        /// GGX Fresnel reflectance per channel.
        f0: [f64; 3],
    },
}

fn smith_lambda(w: Vec3, ax: f64, ay: f64) -> f64 {
    let c2 = (w[2] * w[2]).max(MIN_COS * MIN_COS);
    let s2 = (w[0] * ax) * (w[0] * ax) + (w[1] * ay) * (w[1] * ay);
    0.5 * (-1.0 + (1.0 + s2 / c2).sqrt())
}

/// GGX normal distribution D(h) (per unit projected area of h's solid angle).
pub(crate) fn ggx_d(h: Vec3, ax: f64, ay: f64) -> f64 {
    let t = (h[0] / ax) * (h[0] / ax) + (h[1] / ay) * (h[1] / ay) + h[2] * h[2];
    1.0 / (PI * ax * ay * t * t)
}

/// Smith G₁ for GGX.
pub(crate) fn ggx_g1(w: Vec3, ax: f64, ay: f64) -> f64 {
    1.0 / (1.0 + smith_lambda(w, ax, ay))
}

fn half(wi: Vec3, wo: Vec3) -> Option<Vec3> {
    let h = [wi[0] + wo[0], wi[1] + wo[1], wi[2] + wo[2]];
    crate::sampler::normalize(h)
}

impl Analytic {
    /// Whether f depends on the incident azimuth (other than through φ_o − φ_i).
    pub fn symmetry(&self) -> Symmetry {
        match *self {
            Analytic::Ggx {
                alpha_x, alpha_y, ..
            } if alpha_x != alpha_y => Symmetry::Anisotropic,
            Analytic::AshikhminShirley { nu, nv, .. } if nu != nv => Symmetry::Anisotropic,
            _ => Symmetry::Isotropic,
        }
    }

    /// A short name for tables and reports.
    pub fn name(&self) -> &'static str {
        match (self, self.symmetry()) {
            (Analytic::Lambert { .. }, _) => "lambert",
            (Analytic::Ggx { .. }, Symmetry::Isotropic) => "ggx",
            (Analytic::Ggx { .. }, Symmetry::Anisotropic) => "ggx-aniso",
            (Analytic::AshikhminShirley { .. }, _) => "ashikhmin-shirley",
            (Analytic::Mix { .. }, _) => "mix",
        }
    }

    /// The families of the tests and of the experiment, with their parameters.
    pub fn families() -> Vec<Analytic> {
        vec![
            Analytic::Lambert {
                albedo: [0.8, 0.5, 0.2],
            },
            Analytic::Ggx {
                alpha_x: 0.3,
                alpha_y: 0.3,
                f0: [0.9, 0.7, 0.5],
            },
            Analytic::Ggx {
                alpha_x: 0.2,
                alpha_y: 0.5,
                f0: [0.9, 0.9, 0.9],
            },
            Analytic::AshikhminShirley {
                nu: 20.0,
                nv: 80.0,
                rs: [0.6, 0.6, 0.7],
            },
            Analytic::Mix {
                kd: [0.4, 0.3, 0.2],
                alpha: 0.25,
                f0: [0.5, 0.5, 0.5],
            },
        ]
    }

    /// f_r per channel at unit directions (0 below the horizon).
    pub fn eval(&self, wi: Vec3, wo: Vec3) -> [f64; 3] {
        if !(wi[2] >= 0.0 && wo[2] >= 0.0) {
            return [0.0; 3];
        }
        let (ci, co) = (wi[2].max(MIN_COS), wo[2].max(MIN_COS));
        let ggx = |ax: f64, ay: f64, f0: [f64; 3]| -> [f64; 3] {
            let Some(h) = half(wi, wo) else {
                return [0.0; 3];
            };
            let g2 = 1.0 / (1.0 + smith_lambda(wi, ax, ay) + smith_lambda(wo, ax, ay));
            let s = ggx_d(h, ax, ay) * g2 / (4.0 * ci * co);
            [s * f0[0], s * f0[1], s * f0[2]]
        };
        match *self {
            Analytic::Lambert { albedo } => albedo.map(|a| a / PI),
            Analytic::Ggx {
                alpha_x,
                alpha_y,
                f0,
            } => ggx(alpha_x, alpha_y, f0),
            Analytic::AshikhminShirley { nu, nv, rs } => {
                let Some(h) = half(wi, wo) else {
                    return [0.0; 3];
                };
                let hk = (h[0] * wi[0] + h[1] * wi[1] + h[2] * wi[2]).max(MIN_COS);
                let st2 = (h[0] * h[0] + h[1] * h[1]).max(1e-300);
                let e = if st2 > 1e-300 {
                    (nu * h[0] * h[0] + nv * h[1] * h[1]) / st2
                } else {
                    nu
                };
                let lobe = ((nu + 1.0) * (nv + 1.0)).sqrt() / (8.0 * PI) * h[2].max(0.0).powf(e)
                    / (hk * ci.max(co));
                let f5 = (1.0 - hk).powi(5);
                rs.map(|r| lobe * (r + (1.0 - r) * f5))
            }
            Analytic::Mix { kd, alpha, f0 } => {
                let s = ggx(alpha, alpha, f0);
                [kd[0] / PI + s[0], kd[1] / PI + s[1], kd[2] / PI + s[2]]
            }
        }
    }

    /// f_r at angles (radians, absolute azimuths).
    pub fn eval_angles(&self, ti: f64, pi: f64, to: f64, po: f64) -> [f64; 3] {
        self.eval(direction(ti, pi), direction(to, po))
    }

    /// The table of this BRDF on uniform grids: `n_theta` polar nodes 0°…90° (incident and
    /// outgoing), `n_phi` outgoing azimuths (Δφ for isotropic BRDFs), and `n_phi` incident
    /// azimuths for anisotropic ones. Three channels.
    pub fn table(&self, n_theta: usize, n_phi: usize) -> Result<TabulatedBrdf, BrdfError> {
        let sym = self.symmetry();
        let phi_i = match sym {
            Symmetry::Isotropic => vec![0.0],
            Symmetry::Anisotropic => uniform_phi(n_phi),
        };
        TabulatedBrdf::from_fn(
            sym,
            3,
            uniform_theta(n_theta, 90.0),
            phi_i,
            uniform_theta(n_theta, 90.0),
            uniform_phi(n_phi),
            |ti, pi, to, po| match sym {
                Symmetry::Isotropic => self.eval_angles(ti, 0.0, to, po),
                Symmetry::Anisotropic => self.eval_angles(ti, pi, to, po),
            },
        )
    }
}
