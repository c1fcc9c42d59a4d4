//! Woven cloth: Irawan and Marschner's yarn highlight ("Specular Reflection from Woven Cloth",
//! ACM TOG 2012; P. Irawan's thesis "The Appearance of Woven Cloth", 2008) over a diffuse
//! base, as LuxRender 1.x's `cloth` material has it (which took it from Mitsuba).
//!
//! A weave is a tile of yarn segments ([`crate::material::cloth::Preset`]); the material finds
//! which segment a hit lies on and where on it ([`crate::material::cloth`]), and this lobe
//! evaluates the highlight of that point of that segment: the fibres of a bent, twisted yarn
//! reflect where their normal is the half vector, a narrow band whose brightness is the
//! segment's geometry factor times a phase function (uniform plus von Mises forward
//! scattering) times Seeliger's attenuation.
//! Filament yarns (no twist) and staple yarns (twisted fibres) have different band shapes.
//!
//! f = Kd / pi + Ks s N I(wo, wi) / pi, with I the highlight integrand (symmetric in its two
//! directions), N the preset's normalisation (the mean of N I over cosine-distributed
//! direction pairs and points of the weave is 1) and s the fibre's glint factor (mean 1, up
//! to 10). That is LuxRender's lobe, and it lets a point reflect up to ten times what it
//! receives (and, with Ks = 1, the weave on average 1.8 times at grazing angles). Here s is
//! capped for each pair of directions: with A(theta) a bound of the directional albedo of N I
//! over every point of the weave for outgoing directions at theta (measured per preset),
//! s <= (1 - Kd) / (Ks A) at both theta_o and theta_i, so Kd + Ks s N A <= 1 from every
//! direction and the cap, being symmetric, keeps the lobe reciprocal. Highlights that
//! LuxRender renders brighter than energy allows are dimmer here. Sampling is
//! cosine-weighted, as in LuxRender.

use std::f32::consts::{FRAC_1_PI, FRAC_PI_2, PI};

use glam::{Vec2, Vec3};

use super::local::same_hemisphere;
use super::lobe::Lobe;
use super::sample::{cosine_pdf, LocalSample};

/// Whether a yarn runs along v (warp) or along u (weft, the same geometry turned a quarter).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum YarnKind {
    Warp,
    Weft,
}

/// One yarn segment of a weave: a rectangle of the tile, in tile cells, and its fibres' shape.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Yarn {
    pub kind: YarnKind,
    /// Fibre twist angle, radians (0: a filament yarn).
    pub psi: f32,
    /// Largest inclination of the yarn's spine, radians.
    pub umax: f32,
    /// Spine curvature (-1 < kappa: ellipse, parabola or hyperbola).
    pub kappa: f32,
    pub width: f32,
    pub length: f32,
    /// Centre of the segment in the tile, both in [0, 1] of the tile (may lie outside it for a
    /// segment that wraps around the tile's edge).
    pub center: Vec2,
}

/// The weave-wide parameters of the highlight.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Scattering {
    /// Uniform part of the phase function.
    pub alpha: f32,
    /// Concentration of the forward-scattering (von Mises) part.
    pub beta: f32,
    /// Fraction of the spine, at its ends, over which the highlight fades out (filaments).
    pub smoothing: f32,
    /// Width of the highlight band, as a fraction of the yarn's angular range.
    pub highlight_width: f32,
    /// Parts of the tile's area covered by warp and by weft.
    pub warp_area: f32,
    pub weft_area: f32,
}

impl Yarn {
    /// The highlight integrand at point (u, v) of the segment (u along the spine in
    /// [-umax, umax], v across it in [-pi/2, pi/2]) for directions in the upper hemisphere;
    /// `umax` is the segment's inclination after its noise.
    pub fn integrand(&self, s: &Scattering, at: Vec2, umax: f32, wi: Vec3, wo: Vec3) -> f32 {
        let (wi, wo, area) = match self.kind {
            YarnKind::Warp => (wi, wo, s.warp_area),
            // A quarter turn about the normal maps the weft onto the warp's geometry.
            YarnKind::Weft => (
                Vec3::new(-wi.y, wi.x, wi.z),
                Vec3::new(-wo.y, wo.x, wo.z),
                s.weft_area,
            ),
        };
        if area <= 0.0 || self.width * libm::sinf(umax) >= self.length || self.kappa < -1.0 {
            return 0.0;
        }
        let value = if self.psi == 0.0 {
            self.filament(s, at, umax, wi, wo)
        } else {
            self.staple(s, at, umax, wi, wo)
        };
        value * (s.warp_area + s.weft_area) / area
    }

    /// A yarn of parallel untwisted fibres: the highlight lies where the spine's inclination
    /// u(v) faces the half vector.
    fn filament(&self, s: &Scattering, at: Vec2, umax: f32, wi: Vec3, wo: Vec3) -> f32 {
        if !(0.0..1.0).contains(&s.smoothing) {
            return 0.0;
        }
        let sum = wi + wo;
        let h = sum.normalize_or_zero();
        let u_h = libm::atan2f(h.y, h.z);
        let half_band = umax * s.highlight_width;
        if u_h.abs() >= umax || (u_h - at.x).abs() >= half_band {
            return 0.0;
        }
        let (sin_u, cos_u) = libm::sincosf(u_h);
        let (sin_v, cos_v) = libm::sincosf(at.y);
        let n = Vec3::new(sin_v, sin_u * cos_v, cos_u * cos_v).normalize_or_zero();
        let t = Vec3::new(0.0, cos_u, -sin_u);
        let end = (1.0 - s.smoothing) * umax;
        let r = self.radius_of_curvature(u_h.abs().min(end), end);
        let a = 0.5 * self.width;
        let geometry = a * (r + a * cos_v) / (sum.length() * t.cross(h).x.abs());
        let mut attenuation = seeliger(n.dot(wi), n.dot(wo));
        if s.smoothing > 0.0 {
            attenuation *= smooth_step((umax - u_h.abs()) / (s.smoothing * umax));
        }
        // The band of width 2 umax hwidth in u spread over the segment's u range.
        geometry * phase(s, wi, wo) * attenuation * PI / s.highlight_width
    }

    /// A yarn of twisted fibres: the highlight lies where the fibres at spine position u face
    /// the half vector, a v(u) across the yarn.
    fn staple(&self, s: &Scattering, at: Vec2, umax: f32, wi: Vec3, wo: Vec3) -> f32 {
        let sum = wi + wo;
        let h = sum.normalize_or_zero();
        let (sin_u, cos_u) = libm::sincosf(at.x);
        let across = h.y * sin_u + h.z * cos_u;
        let d = (h.y * cos_u - h.z * sin_u)
            / ((h.x * h.x + across * across).sqrt() * libm::tanf(self.psi));
        // NaN (a degenerate half vector) fails too.
        if d.is_nan() || d.abs() >= 1.0 {
            return 0.0;
        }
        let v_h = libm::atan2f(-across, h.x) + libm::acosf(d);
        if (v_h - at.y).abs() >= FRAC_PI_2 * s.highlight_width {
            return 0.0;
        }
        let (sin_v, cos_v) = libm::sincosf(v_h);
        let n = Vec3::new(sin_v, sin_u * cos_v, cos_u * cos_v).normalize_or_zero();
        let r = self.radius_of_curvature(at.x.abs(), umax);
        let a = 0.5 * self.width;
        let geometry = a * (r + a * cos_v) / (sum.length() * n.dot(h) * libm::sinf(self.psi).abs());
        let value = geometry * phase(s, wi, wo) * seeliger(n.dot(wi), n.dot(wo));
        // The band spread over the segment's v range.
        value * 2.0 * umax / s.highlight_width
    }

    /// Radius of curvature of the spine at inclination u: an arc of an ellipse, parabola or
    /// hyperbola by kappa (Irawan's thesis, section 5.3).
    fn radius_of_curvature(&self, u: f32, umax: f32) -> f32 {
        let rhat = 1.0 + self.kappa * (1.0 + 1.0 / libm::tanf(umax));
        let a = 0.5 * self.width;
        let reach = 0.5 * self.length - a * libm::sinf(umax);
        if rhat == 1.0 {
            0.5 * self.length / libm::sinf(umax) - a
        } else if rhat > 0.0 {
            let bhat = reach / libm::sinf(libm::atanf(rhat * libm::tanf(umax)));
            let ahat = bhat / rhat;
            let t = libm::atanf(rhat * libm::tanf(u));
            let (st, ct) = libm::sincosf(t);
            libm::powf(bhat * bhat * ct * ct + ahat * ahat * st * st, 1.5) / (ahat * bhat)
        } else if rhat < 0.0 {
            let bhat = reach / libm::sinhf(-libm::atanhf(rhat * libm::tanf(umax)));
            let ahat = bhat / rhat;
            let t = -libm::atanhf(rhat * libm::tanf(u));
            let (sh, ch) = (libm::sinhf(t), libm::coshf(t));
            -libm::powf(bhat * bhat * ch * ch + ahat * ahat * sh * sh, 1.5) / (ahat * bhat)
        } else {
            let ahat = reach / (2.0 * libm::tanf(umax));
            let t = libm::tanf(u);
            2.0 * ahat * libm::powf(1.0 + t * t, 1.5)
        }
    }
}

/// The fibres' phase function: uniform plus von Mises about the forward direction.
fn phase(s: &Scattering, wi: Vec3, wo: Vec3) -> f32 {
    s.alpha + von_mises(-wi.dot(wo), s.beta)
}

/// The von Mises density exp(b cos x) / (2 pi I0(b)), with I0 by Abramowitz and Stegun's
/// polynomials (9.8.1, 9.8.2); for large b written so that exp(b) never overflows.
fn von_mises(cos_x: f32, b: f32) -> f32 {
    let b = b.abs();
    if b <= 3.75 {
        let t = (b / 3.75).powi(2);
        let i0 = 1.0
            + t * (3.515_623
                + t * (3.089_942_4
                    + t * (1.206_749_2 + t * (0.265_973_2 + t * (0.036_076_8 + t * 0.004_581_3)))));
        libm::expf(b * cos_x) / (2.0 * PI * i0)
    } else {
        let t = 3.75 / b;
        // I0(b) = exp(b) / sqrt(b) * poly(t).
        let poly = 0.398_942_3
            + t * (0.013_285_92
                + t * (0.002_253_19
                    + t * (-0.001_575_65
                        + t * (0.009_162_81
                            + t * (-0.020_577_06
                                + t * (0.026_355_37 + t * (-0.016_476_33 + t * 0.003_923_77)))))));
        libm::expf(b * (cos_x - 1.0)) * b.sqrt() / (2.0 * PI * poly)
    }
}

/// Seeliger's law for a purely scattering medium: single scattering from a half-space,
/// c1 c2 / (c1 + c2) / (4 pi).
fn seeliger(cos_1: f32, cos_2: f32) -> f32 {
    let (c1, c2) = (cos_1.max(0.0), cos_2.max(0.0));
    if c1 == 0.0 || c2 == 0.0 {
        return 0.0;
    }
    0.25 * FRAC_1_PI * c1 * c2 / (c1 + c2)
}

/// 3x^2 - 2x^3 on x clamped to [0, 1].
fn smooth_step(x: f32) -> f32 {
    let x = x.clamp(0.0, 1.0);
    x * x * (3.0 - 2.0 * x)
}

/// Steps of the directional-albedo bound: at cos(theta_o) = 1, 0.9, ..., 0.
pub const ALBEDO_STEPS: usize = 11;

/// Where a hit lies on a yarn and how bright its highlight is.
#[derive(Clone, Copy, Debug)]
pub struct Highlight {
    pub yarn: &'static Yarn,
    pub scattering: &'static Scattering,
    /// The point on the segment: (u along the spine, v across), radians.
    pub at: Vec2,
    /// The segment's inclination after its noise.
    pub umax: f32,
    /// The fibre's glint factor (1 without glints).
    pub glint: f32,
    /// LuxRender's specular normalisation: 1 / the integrand's mean over the weave.
    pub normalization: f32,
    /// A bound of the normalised integrand's directional albedo over every point of the weave,
    /// at each step of cos(theta_o) ([`ALBEDO_STEPS`]).
    pub albedo_bound: &'static [f32; ALBEDO_STEPS],
}

impl Highlight {
    /// The highlight integrand I (scale 1) for two directions in the upper hemisphere.
    pub fn integrand(&self, wo: Vec3, wi: Vec3) -> f32 {
        self.yarn
            .integrand(self.scattering, self.at, self.umax, wi, wo)
    }

    /// The bound of the normalised directional albedo for directions at `cos` from the normal:
    /// the larger of the bounds at the two steps around it.
    fn albedo_bound(&self, cos: f32) -> f32 {
        let x = (1.0 - cos.abs().min(1.0)) * (ALBEDO_STEPS - 1) as f32;
        let k = (x as usize).min(ALBEDO_STEPS - 2);
        self.albedo_bound[k].max(self.albedo_bound[k + 1])
    }
}

/// The cloth lobe at one point of one yarn segment.
#[derive(Clone, Copy, Debug)]
pub struct Cloth {
    kd: Vec3,
    ks: Vec3,
    highlight: Highlight,
    /// The largest glint factor with which kd + ks glint A stays <= 1 in every channel for a
    /// normalised directional albedo A of 1.
    room: f32,
}

impl Cloth {
    /// `kd`, `ks` the yarn's colours, clamped to [0, 1].
    pub fn new(kd: Vec3, ks: Vec3, highlight: Highlight) -> Self {
        let kd = kd.clamp(Vec3::ZERO, Vec3::ONE);
        let ks = ks.clamp(Vec3::ZERO, Vec3::ONE);
        let room = ((Vec3::ONE - kd) / ks).min_element();
        Self {
            kd,
            ks,
            highlight,
            room: if room.is_nan() { 0.0 } else { room.max(0.0) },
        }
    }

    /// The glint factor used for the pair (wo, wi): LuxRender's, capped so that the albedo
    /// from either direction stays within what the diffuse part leaves (symmetric, so the
    /// lobe stays reciprocal).
    fn scale(&self, wo: Vec3, wi: Vec3) -> f32 {
        let h = &self.highlight;
        let cap = |w: Vec3| self.room / h.albedo_bound(w.z);
        h.glint.min(cap(wo)).min(cap(wi)) * h.normalization
    }
}

impl Lobe for Cloth {
    const GATHERS_BROADLY: bool = true;

    /// What it reflects at most, for lobe selection under a coat.
    fn albedo_hint(&self, _cos_o: f32) -> Vec3 {
        (self.kd + self.ks * self.room).min(Vec3::ONE)
    }

    /// `wo` is in the upper hemisphere (the BSDF mirrors back-face queries).
    fn f(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        if !same_hemisphere(wo, wi) || wi.z == 0.0 || wo.z == 0.0 {
            return Vec3::ZERO;
        }
        let highlight = self.highlight.integrand(wo, wi) * self.scale(wo, wi);
        let highlight = if highlight.is_finite() {
            highlight.max(0.0)
        } else {
            0.0
        };
        (self.kd + self.ks * highlight) * FRAC_1_PI
    }

    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        cosine_pdf(wo, wi)
    }

    fn sample(&self, wo: Vec3, _u_lobe: f32, u: Vec2) -> Option<LocalSample> {
        LocalSample::cosine(wo, u, |wi| self.f(wo, wi))
    }
}
