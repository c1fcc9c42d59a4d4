//! The BSDF at a surface point in world space: a local scattering function in the shading
//! frame, possibly under a glossy coating, guarded by the geometric normal against light
//! leaks.

use glam::{Vec2, Vec3};

use super::coat_over_base::Coating;
use super::sample::LocalSample;
use super::Bxdf;
use crate::math::{Cone, Frame};
use crate::wavelength::Wavelength;

/// A sampled scattering direction.
#[derive(Clone, Copy, Debug)]
pub struct BsdfSample {
    /// Unit world-space direction away from the surface.
    pub wi: Vec3,
    /// BSDF value for (wo, wi), not multiplied by the cosine.
    pub f: Vec3,
    /// Solid-angle density; for specular lobes the discrete probability of the lobe.
    pub pdf: f32,
    pub specular: bool,
}

/// The BSDF at one surface point, in world space. Plain data: building one allocates nothing.
///
/// Shading normals make the shading frame disagree with the true surface near silhouettes. A
/// pair of directions counts as a reflection only when both the shading normal and the
/// geometric normal see them on the same side (and as a transmission only when both see them
/// on opposite sides); otherwise the BSDF is zero, so light never leaks through a surface and
/// a reflection never comes from below it.
#[derive(Clone, Copy, Debug)]
pub struct Bsdf {
    frame: Frame,
    ng: Vec3,
    bxdf: Bxdf,
    coating: Option<Coating>,
}

impl Bsdf {
    /// `frame.n` is the shading normal; `ng` the geometric normal (either orientation).
    pub(crate) fn new(frame: Frame, ng: Vec3, bxdf: Bxdf, coating: Option<Coating>) -> Self {
        Self {
            frame,
            ng,
            bxdf,
            coating,
        }
    }

    /// True when the material is `null`: the ray continues straight through.
    pub fn is_pass_through(&self) -> bool {
        matches!(self.bxdf, Bxdf::PassThrough(_))
    }

    /// What a pane of architectural glass lets straight through along `w` (either way), as a
    /// shadow ray crossing it sees it: see
    /// [`Dielectric::straight_transmittance`](super::dielectric::Dielectric::straight_transmittance). None for
    /// every other BSDF.
    pub fn straight_transmittance(&self, w: Vec3) -> Option<Vec3> {
        match (&self.bxdf, &self.coating) {
            (Bxdf::Dielectric(d), None) => d.straight_transmittance(self.frame.to_local(w)),
            _ => None,
        }
    }

    /// For a pane of architectural glass, the weight of the straight transmission when
    /// `u_lobe` chooses it over the reflection (the choice [`Self::sample`] makes with the same
    /// `u_lobe`); None when it reflects, and for every other BSDF.
    pub fn sample_straight(&self, wo: Vec3, u_lobe: f32) -> Option<Vec3> {
        match (&self.bxdf, &self.coating) {
            (Bxdf::Dielectric(d), None) => d.sample_straight(self.frame.to_local(wo), u_lobe),
            _ => None,
        }
    }

    /// A bare Lambert BSDF's shading frame, geometric normal and value (the same for every
    /// pair of directions it reflects): what a path traced in lanes shades with. None for
    /// every other BSDF, and for a value that is zero or not finite.
    pub fn as_lambert(&self) -> Option<(Frame, Vec3, Vec3)> {
        let (Bxdf::Diffuse(d), None) = (&self.bxdf, &self.coating) else {
            return None;
        };
        let f = d.lambert_value()?;
        (f != Vec3::ZERO && f.is_finite()).then_some((self.frame, self.ng, f))
    }

    /// Whether the BSDF bends each wavelength its own way ([`Dielectric::is_dispersive`](super::dielectric::Dielectric::is_dispersive)):
    /// a path takes one wavelength here ([`Self::disperse`]).
    pub fn is_dispersive(&self) -> bool {
        matches!(&self.bxdf, Bxdf::Dielectric(d) if d.is_dispersive())
    }

    /// The BSDF as a path meets it: a dispersive one takes the path's wavelength (`carried`),
    /// or, at the path's first dispersive vertex, draws it from `number()` and returns the RGB
    /// weight the path carries from here on ([`crate::wavelength`]). Any other is left as it is.
    pub fn disperse(
        &mut self,
        carried: &mut Option<Wavelength>,
        number: impl FnOnce() -> f32,
    ) -> Option<Vec3> {
        let Bxdf::Dielectric(d) = &mut self.bxdf else {
            return None;
        };
        if !d.is_dispersive() {
            return None;
        }
        let mut drawn = None;
        let wavelength = *carried.get_or_insert_with(|| {
            let w = Wavelength::draw(number());
            drawn = Some(w.weight);
            w
        });
        d.at_wavelength(wavelength.nm);
        drawn
    }

    /// True when every lobe is specular (light sampling is useless here).
    pub fn is_specular(&self) -> bool {
        match &self.coating {
            Some(c) => c.is_specular(&self.bxdf),
            None => self.bxdf.is_specular(),
        }
    }

    /// For a BSDF that reflects only, and broadly ([`Bxdf::gathers_broadly`]), the shading
    /// normal on `wo`'s side: all the light it scatters towards `wo` comes from that hemisphere,
    /// weighed much as by the cosine (the light sample's environment maps are sampled for it).
    /// None for other BSDFs.
    pub fn gathers_from(&self, wo: Vec3) -> Option<Vec3> {
        self.bxdf.gathers_broadly().then(|| {
            let n = self.frame.n;
            if wo.dot(n) < 0.0 {
                -n
            } else {
                n
            }
        })
    }

    /// Roughly what the surface reflects and transmits of light leaving along `wo` (its lobe's
    /// albedo hint, a coating left out): the albedo AOV's value.
    pub fn albedo(&self, wo: Vec3) -> Vec3 {
        self.bxdf.albedo_hint(self.frame.to_local(wo).z.abs())
    }

    /// The shading normal (world space) on `wo`'s side.
    pub fn shading_normal_toward(&self, wo: Vec3) -> Vec3 {
        let n = self.frame.n;
        if wo.dot(n) < 0.0 {
            -n
        } else {
            n
        }
    }

    /// The cone around `wo`'s mirror direction about the shading normal (world space) that
    /// holds most of a bare glossy lobe ([`Bxdf::glossy_spread`]; a coated one is not counted).
    pub fn glossy_cone(&self, wo: Vec3) -> Option<Cone> {
        let half = self
            .coating
            .is_none()
            .then(|| self.bxdf.glossy_spread())??;
        let n = self.frame.n;
        let axis = (2.0 * wo.dot(n) * n - wo).normalize();
        Some(Cone { axis, half })
    }

    /// Whether the geometric and shading normals agree on which side `wi` is on relative
    /// to `wo`.
    fn sides_agree(&self, wo: Vec3, wi: Vec3, wo_local: Vec3, wi_local: Vec3) -> bool {
        let geometric = wo.dot(self.ng) * wi.dot(self.ng);
        let shading = wo_local.z * wi_local.z;
        (geometric > 0.0 && shading > 0.0) || (geometric < 0.0 && shading < 0.0)
    }

    /// f(wo, wi) for the non-specular lobes; wo and wi are unit world directions away from
    /// the surface.
    // Inlined into the path loop, as `pdf` is: the loop is large enough that the compiler
    // leaves it out of line otherwise (bench/RESULTS.md, "Figures moved out of the code").
    #[inline(always)]
    pub fn eval(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        let (wo_local, wi_local) = (self.frame.to_local(wo), self.frame.to_local(wi));
        if !self.sides_agree(wo, wi, wo_local, wi_local) {
            return Vec3::ZERO;
        }
        match &self.coating {
            Some(c) => c.f(&self.bxdf, wo_local, wi_local),
            None => self.bxdf.f(wo_local, wi_local),
        }
    }

    /// Density with which `sample` picks wi (non-specular lobes only).
    // Inlined into the path loop, where it is hot; the mirror-image light sample calls it too,
    // and a second call site would otherwise leave it out of line.
    #[inline(always)]
    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        let (wo, wi) = (self.frame.to_local(wo), self.frame.to_local(wi));
        match &self.coating {
            Some(c) => c.pdf(&self.bxdf, wo, wi),
            None => self.bxdf.pdf(wo, wi),
        }
    }

    /// Samples wi given wo; `u_lobe` picks a lobe, `u` the direction.
    // As `pdf`.
    #[inline(always)]
    pub fn sample(&self, wo: Vec3, u_lobe: f32, u: Vec2) -> Option<BsdfSample> {
        let wo_local = self.frame.to_local(wo);
        let LocalSample {
            wi: wi_local,
            f,
            pdf,
            specular,
        } = match &self.coating {
            Some(c) => c.sample(&self.bxdf, wo_local, u_lobe, u),
            None => self.bxdf.sample(wo_local, u_lobe, u),
        }?;
        let wi = self.frame.to_world(wi_local).normalize();
        if !self.sides_agree(wo, wi, wo_local, wi_local) || f == Vec3::ZERO {
            return None;
        }
        Some(BsdfSample {
            wi,
            f,
            pdf,
            specular,
        })
    }
}
