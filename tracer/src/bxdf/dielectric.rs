//! Dielectric interfaces: smooth glass (specular reflection and refraction), rough glass
//! (Walter et al. 2007 microfacet reflection and transmission) and architectural glass (a thin
//! pane: no bend, internal reflections summed).
//!
//! Transmitted radiance is not scaled by 1/eta^2. Cameras and lights sit outside glass in the
//! scenes YAT renders, so on a closed object the factors of entering and leaving cancel; and
//! without them an open glass surface (a single-sided windshield) does not darken what is
//! behind it. It also makes every dielectric's directional albedo at most 1.

use glam::{Vec2, Vec3};

use super::fresnel;
use super::local::{reflect, refract, same_hemisphere};
use super::microfacet::TrowbridgeReitz;
use super::lobe::Lobe;
use super::sample::LocalSample;
use super::thin_film::ThinFilm;
use crate::wavelength::Dispersion;

#[derive(Clone, Copy, Debug)]
pub enum Surface {
    Smooth,
    Rough(TrowbridgeReitz),
    /// Architectural glass: a thin pane, smooth.
    Thin,
}

#[derive(Clone, Copy, Debug)]
pub struct Dielectric {
    /// Tints of the reflected and transmitted light.
    pub kr: Vec3,
    pub kt: Vec3,
    /// Index of the inside relative to the outside (the side the normal points to).
    pub eta: f32,
    pub surface: Surface,
    /// Interference on the smooth or thin surface's reflection (LuxRender's glass; its rough
    /// glass has none).
    pub film: Option<ThinFilm>,
    /// How the index depends on a path's wavelength ([`Self::at_wavelength`]): glass's
    /// `cauchyb` (`eta + b / nm^2`), glass2's volumes' indices, or not at all.
    pub dispersion: Dispersion,
}

impl Dielectric {
    /// Whether the interface bends each wavelength its own way, so a path crossing it takes
    /// one wavelength ([`crate::wavelength`]). A pane does not bend light: its dispersion
    /// changes only its faces' reflectance, by a few parts in a thousand, which is left out.
    pub fn is_dispersive(&self) -> bool {
        self.dispersion.varies() && !matches!(self.surface, Surface::Thin)
    }

    /// The interface as a path of wavelength `nm` meets it: its index there.
    pub fn at_wavelength(&mut self, nm: f32) {
        let eta = self.dispersion.index(self.eta, nm);
        // A negative B can take the index through zero (and a Sellmeier pole to infinity): no
        // interface then, as a non-positive index is everywhere else.
        self.eta = if eta > 0.0 && eta.is_finite() { eta } else { 1.0 };
        self.dispersion = Dispersion::None;
    }

    /// The tint of the mirror reflection at `cos` to the normal: Kr, and the film's
    /// interference over it.
    fn reflected_tint(&self, cos: f32) -> Vec3 {
        match self.film {
            Some(film) => self.kr * film.weight(cos.abs()),
            None => self.kr,
        }
    }

    /// Probability of choosing reflection given Fresnel reflectance `r`: in proportion to the
    /// reflected and transmitted energy, so a black tint is never sampled.
    fn reflect_probability(&self, r: f32) -> f32 {
        let pr = r * self.kr.max_element();
        let pt = (1.0 - r) * self.kt.max_element();
        if pr + pt > 0.0 {
            pr / (pr + pt)
        } else {
            0.0
        }
    }

    fn sample_smooth(&self, wo: Vec3, u_lobe: f32) -> Option<LocalSample> {
        if wo.z == 0.0 {
            return None;
        }
        let r = fresnel::dielectric(wo.z, self.eta);
        let p_reflect = self.reflect_probability(r);
        if u_lobe < p_reflect {
            let wi = Vec3::new(-wo.x, -wo.y, wo.z);
            LocalSample::specular(wi, self.reflected_tint(wo.z) * (r / wi.z.abs()), p_reflect)
        } else {
            let (wi, _) = refract(wo, Vec3::Z, self.eta)?;
            if wi.z == 0.0 {
                return None;
            }
            LocalSample::specular(wi, self.kt * ((1.0 - r) / wi.z.abs()), 1.0 - p_reflect)
        }
    }

    /// A thin pane seen along `wo`: its reflectance, the internal reflections between its two
    /// faces summed as a geometric series (pbrt-v4's ThinDielectricBxDF), and the probability
    /// of sampling the reflection.
    fn thin_split(&self, wo: Vec3) -> (f32, f32) {
        let mut r = fresnel::dielectric(wo.z.abs(), self.eta);
        if r < 1.0 {
            r += (1.0 - r) * (1.0 - r) * r / (1.0 - r * r);
        }
        (r, self.reflect_probability(r))
    }

    fn sample_thin(&self, wo: Vec3, u_lobe: f32) -> Option<LocalSample> {
        if wo.z == 0.0 {
            return None;
        }
        let (r, p_reflect) = self.thin_split(wo);
        if u_lobe < p_reflect {
            let wi = Vec3::new(-wo.x, -wo.y, wo.z);
            LocalSample::specular(wi, self.reflected_tint(wo.z) * (r / wi.z.abs()), p_reflect)
        } else {
            let wi = -wo;
            LocalSample::specular(wi, self.kt * ((1.0 - r) / wi.z.abs()), 1.0 - p_reflect)
        }
    }

    /// What a pane of architectural glass lets straight through along `wo` (either way):
    /// its transmission tint times the light its faces do not reflect. None for every other
    /// interface, which bends or scatters what it transmits.
    pub fn straight_transmittance(&self, wo: Vec3) -> Option<Vec3> {
        if !matches!(self.surface, Surface::Thin) || wo.z == 0.0 {
            return None;
        }
        let (r, _) = self.thin_split(wo);
        Some(self.kt * (1.0 - r))
    }

    /// The pane's lobe choice of [`Lobe::sample`] for `u_lobe`, when it is the straight
    /// transmission: the sample's weight (f cos / pdf). None when it reflects, and for every
    /// other interface.
    pub fn sample_straight(&self, wo: Vec3, u_lobe: f32) -> Option<Vec3> {
        if !matches!(self.surface, Surface::Thin) || wo.z == 0.0 {
            return None;
        }
        let (r, p_reflect) = self.thin_split(wo);
        (u_lobe >= p_reflect).then(|| self.kt * ((1.0 - r) / (1.0 - p_reflect)))
    }

    /// The generalized half vector of a reflection or refraction pair, facing up; None for
    /// configurations no microfacet can produce.
    fn half_vector(&self, wo: Vec3, wi: Vec3) -> Option<(Vec3, f32)> {
        let (cos_o, cos_i) = (wo.z, wi.z);
        if cos_o == 0.0 || cos_i == 0.0 {
            return None;
        }
        let reflect = cos_o * cos_i > 0.0;
        let etap = if reflect {
            1.0
        } else if cos_o > 0.0 {
            self.eta
        } else {
            1.0 / self.eta
        };
        let wm = wi * etap + wo;
        if wm.length_squared() == 0.0 {
            return None;
        }
        let mut wm = wm.normalize();
        if wm.z < 0.0 {
            wm = -wm;
        }
        // Microfacets seen from behind scatter nothing.
        if wm.dot(wi) * cos_i < 0.0 || wm.dot(wo) * cos_o < 0.0 {
            return None;
        }
        Some((wm, etap))
    }

    /// f and pdf of rough glass together (they share the half vector and Fresnel term).
    fn rough_f_pdf(&self, distrib: TrowbridgeReitz, wo: Vec3, wi: Vec3) -> (Vec3, f32) {
        let Some((wm, etap)) = self.half_vector(wo, wi) else {
            return (Vec3::ZERO, 0.0);
        };
        let r = fresnel::dielectric(wo.dot(wm), self.eta);
        let p_reflect = self.reflect_probability(r);
        let (cos_o, cos_i) = (wo.z, wi.z);
        if same_hemisphere(wo, wi) {
            let f = self.kr * (distrib.d(wm) * distrib.g(wo, wi) * r / (4.0 * cos_i * cos_o).abs());
            let pdf = distrib.d_visible(wo, wm) / (4.0 * wo.dot(wm).abs()) * p_reflect;
            (f, pdf)
        } else {
            let denom = wi.dot(wm) + wo.dot(wm) / etap;
            let denom2 = denom * denom;
            if denom2 == 0.0 {
                return (Vec3::ZERO, 0.0);
            }
            let f = self.kt
                * (distrib.d(wm)
                    * distrib.g(wo, wi)
                    * (1.0 - r)
                    * (wi.dot(wm) * wo.dot(wm) / (cos_i * cos_o * denom2)).abs());
            let dwm_dwi = wi.dot(wm).abs() / denom2;
            let pdf = distrib.d_visible(wo, wm) * dwm_dwi * (1.0 - p_reflect);
            (f, pdf)
        }
    }

    fn sample_rough(
        &self,
        distrib: TrowbridgeReitz,
        wo: Vec3,
        u_lobe: f32,
        u: Vec2,
    ) -> Option<LocalSample> {
        if wo.z == 0.0 {
            return None;
        }
        let wm = distrib.sample_wm(wo, u);
        let r = fresnel::dielectric(wo.dot(wm), self.eta);
        let wi = if u_lobe < self.reflect_probability(r) {
            let wi = reflect(wo, wm);
            if !same_hemisphere(wo, wi) {
                return None;
            }
            wi
        } else {
            let (wi, _) = refract(wo, wm, self.eta)?;
            if same_hemisphere(wo, wi) || wi.z == 0.0 {
                return None;
            }
            wi
        };
        let (f, pdf) = self.rough_f_pdf(distrib, wo, wi);
        LocalSample::non_specular(wi, f, pdf)
    }
}

impl Lobe for Dielectric {
    /// Glass tells its sides apart: which one a ray leaves by decides the refraction.
    const TWO_SIDED: bool = false;

    fn albedo_hint(&self, _cos_o: f32) -> Vec3 {
        self.kr.max(self.kt)
    }

    fn is_specular(&self) -> bool {
        !matches!(self.surface, Surface::Rough(_)) || self.eta == 1.0
    }

    fn f(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        match self.surface {
            Surface::Rough(distrib) if self.eta != 1.0 => self.rough_f_pdf(distrib, wo, wi).0,
            _ => Vec3::ZERO,
        }
    }

    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        match self.surface {
            Surface::Rough(distrib) if self.eta != 1.0 => self.rough_f_pdf(distrib, wo, wi).1,
            _ => 0.0,
        }
    }

    fn sample(&self, wo: Vec3, u_lobe: f32, u: Vec2) -> Option<LocalSample> {
        match self.surface {
            Surface::Rough(distrib) if self.eta != 1.0 => self.sample_rough(distrib, wo, u_lobe, u),
            Surface::Thin => self.sample_thin(wo, u_lobe),
            _ => self.sample_smooth(wo, u_lobe),
        }
    }
}
