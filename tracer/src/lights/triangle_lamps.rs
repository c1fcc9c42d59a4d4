//! The lights of a scene lit only by a few untextured triangle lamps, as tables that a packet's
//! lanes sample together: the lamp's choice, its triangle's and the point on it are taken in
//! lanes (compares over the few bins, gathers from the tables) with the operations of
//! [`Lights::sample`](super::Lights::sample) in their order, so that every lane gets the bits a
//! path traced alone gets.

use glam::Vec3;

use crate::lanes::{Lanes, U32Lanes};

use super::area::AreaLight;
use super::distribution::{Distribution1D, ONE_MINUS_EPSILON, SCANNED_BINS};

/// Floats a triangle takes in [`TriangleLamps::triangles`]: three vertices and the normal.
const TRIANGLE_FLOATS: usize = 12;

/// Light samples of a packet's lanes ([`super::LightSample`]'s fields).
pub struct LightSamples<L: Lanes> {
    pub wi: [L; 3],
    pub li: [L; 3],
    /// 0 where a lane has no sample (the point shows its back, or the density is not finite).
    pub pdf: L,
    pub dist: L,
    /// 1 where the light is a delta light, else 0 (never, for lamps).
    pub delta: L,
}

/// Tables of every lamp of a scene whose lights are all untextured lamps of at most
/// [`SCANNED_BINS`] triangles, at most [`SCANNED_BINS`] of them. Indices are kept as floats (exact
/// below 2^24) since lanes gather floats.
#[derive(Debug)]
pub struct TriangleLamps {
    /// The lamps' choice: the start of each lamp's bin, and each lamp's probability.
    lamp_starts: Vec<f32>,
    lamp_pmf: Vec<f32>,
    /// Per lamp: its first entry in `triangle_starts`, its first triangle, its triangle count,
    /// 1 / its area, its radiance.
    first_start: Vec<f32>,
    first_triangle: Vec<f32>,
    triangle_count: Vec<f32>,
    pdf_area: Vec<f32>,
    radiance: [Vec<f32>; 3],
    /// Per lamp, its triangles' bin starts by area and a last 1.
    triangle_starts: Vec<f32>,
    /// [`TRIANGLE_FLOATS`] per triangle: the vertices' and the normal's coordinates.
    triangles: Vec<f32>,
    /// The most triangles a lamp has.
    most_triangles: usize,
}

impl TriangleLamps {
    /// The tables of `lamps` (every light of a scene) chosen by `selection`; None unless they
    /// are all untextured triangle lamps, few, of few triangles each.
    pub(super) fn new<'a>(
        lamps: impl ExactSizeIterator<Item = Option<&'a AreaLight>>,
        selection: &Distribution1D,
    ) -> Option<Self> {
        if lamps.len() == 0 || lamps.len() > SCANNED_BINS || selection.len() != lamps.len() {
            return None;
        }
        let mut tables = Self {
            lamp_starts: selection.starts().collect(),
            lamp_pmf: (0..selection.len()).map(|i| selection.pmf(i)).collect(),
            first_start: Vec::new(),
            first_triangle: Vec::new(),
            triangle_count: Vec::new(),
            pdf_area: Vec::new(),
            radiance: Default::default(),
            triangle_starts: Vec::new(),
            triangles: Vec::new(),
            most_triangles: 0,
        };
        for lamp in lamps {
            let (triangles, by_area, area, radiance) = lamp?.plain_triangles()?;
            if triangles.len() > SCANNED_BINS || by_area.len() != triangles.len() {
                return None;
            }
            tables.first_start.push(tables.triangle_starts.len() as f32);
            tables
                .first_triangle
                .push((tables.triangles.len() / TRIANGLE_FLOATS) as f32);
            tables.triangle_count.push(triangles.len() as f32);
            // `AreaLight::sample`'s density on the lamp, the same division.
            tables.pdf_area.push(1.0 / area);
            for (row, value) in tables.radiance.iter_mut().zip(radiance.to_array()) {
                row.push(value);
            }
            tables.triangle_starts.extend(by_area.starts());
            for t in triangles {
                let [p0, p1, p2] = t.vertices;
                tables
                    .triangles
                    .extend([p0, p1, p2, t.n].iter().flat_map(Vec3::to_array));
            }
            tables.most_triangles = tables.most_triangles.max(triangles.len());
        }
        Some(tables)
    }

    /// Light samples as seen from each lane's `from`: `u_select` chooses the lamp, `u` the
    /// triangle and the point on it ([`super::Lights::sample`] one lane at a time).
    #[inline(always)]
    pub fn sample<L: Lanes>(&self, from: [L; 3], u_select: L, u: [L; 2]) -> LightSamples<L> {
        let (zero, one) = (L::splat(0.0), L::splat(1.0));
        // `Distribution1D::sample_discrete`: the last bin starting at or below u.
        let mut lamp = zero;
        for &start in &self.lamp_starts[1..self.lamp_pmf.len()] {
            lamp = lamp + L::select(L::splat(start).le(u_select), one, zero);
        }
        let lamp = lamp.to_u32();
        let pmf = L::gather(&self.lamp_pmf, lamp);
        let (first_start, count) = (
            L::gather(&self.first_start, lamp),
            L::gather(&self.triangle_count, lamp),
        );
        let mut triangle = zero;
        for k in 1..self.most_triangles {
            let k = L::splat(k as f32);
            let inside = k.lt(count);
            let at = L::select(inside, first_start + k, first_start).to_u32();
            let start = L::gather(&self.triangle_starts, at);
            triangle = triangle + L::select(inside & start.le(u[0]), one, zero);
        }
        let at = (first_start + triangle).to_u32();
        let start = L::gather(&self.triangle_starts, at);
        let end = L::gather(&self.triangle_starts, at.wrapping_add(L::U::splat(1)));
        let u0 = (u[0] - start) / (end - start);
        // `f32::clamp(0, ONE_MINUS_EPSILON)`.
        let u0 = L::select(u0.lt(zero), zero, u0);
        let u0 = L::select(
            L::splat(ONE_MINUS_EPSILON).lt(u0),
            L::splat(ONE_MINUS_EPSILON),
            u0,
        );
        // `TriangleSurface::sample`.
        let su0 = u0.sqrt();
        let (b0, b1) = (one - su0, u[1] * su0);
        let b2 = one - b0 - b1;
        let first = (L::gather(&self.first_triangle, lamp) + triangle)
            .to_u32()
            .wrapping_mul(L::U::splat(TRIANGLE_FLOATS as u32));
        // Loops, not closures: a closure would not inherit the caller's target features.
        let mut to_light = [zero; 3];
        let mut n = [zero; 3];
        for c in 0..3 {
            let p = b0 * self.triangle_value(first, c)
                + b1 * self.triangle_value(first, 3 + c)
                + b2 * self.triangle_value(first, 6 + c);
            to_light[c] = p - from[c];
            n[c] = self.triangle_value(first, 9 + c);
        }
        // `AreaLight::sample` from here.
        let dist2 =
            to_light[0] * to_light[0] + to_light[1] * to_light[1] + to_light[2] * to_light[2];
        let dist = dist2.sqrt();
        let mut wi = to_light;
        let mut li = [zero; 3];
        for c in 0..3 {
            wi[c] = to_light[c] / dist;
            li[c] = L::gather(&self.radiance[c], lamp);
        }
        let cos_light = L::splat(-1.0) * (n[0] * wi[0] + n[1] * wi[1] + n[2] * wi[2]);
        let pdf = L::gather(&self.pdf_area, lamp) * dist2 / cos_light;
        let valid = zero.lt(cos_light) & pdf.abs().lt(L::splat(f32::INFINITY));
        LightSamples {
            wi,
            li,
            pdf: L::select(valid, pmf * pdf, zero),
            dist,
            delta: zero,
        }
    }

    /// Float `k` of the triangles whose first floats are at `first`.
    #[inline(always)]
    fn triangle_value<L: Lanes>(&self, first: L::U, k: usize) -> L {
        L::gather(&self.triangles, first.wrapping_add(L::U::splat(k as u32)))
    }
}
