//! One wavelength for a path that meets a dispersive interface (`glass` with `cauchyb`, `glass2`
//! with `dispersion` between volumes whose `fresnel` varies with wavelength), as LuxRender's
//! spectral paths collapse to a single wavelength there. YAT carries RGB, so the
//! path draws the wavelength at its first dispersive vertex from the table below, and from then
//! on carries that wavelength's RGB weight: each wavelength's linear sRGB weight (the weights of
//! each channel sum to 1 over the visible range, [`spectrum_rgb_weights`]) over the probability
//! of drawing it. On average the weight is white, so a dispersive white surface reflects and
//! transmits white light; the spread of its indices over the wavelengths casts the spectra.
//! A leaf module: the integrators draw, the dielectric BxDF takes the wavelength's index.

use std::sync::LazyLock;

use glam::Vec3;

use crate::spectra::spectrum_rgb_weights;

/// The table's spacing in nm: a wavelength is drawn uniformly within its 1 nm bin, so a
/// prism's spectrum is continuous, not banded.
const STEP_NM: f64 = 1.0;

/// A path's wavelength: where it is, in nm, and the RGB weight the path carries from the vertex
/// that drew it on.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Wavelength {
    pub nm: f32,
    pub weight: Vec3,
}

struct Table {
    /// Each bin's centre (nm) and RGB weight over its probability.
    bins: Vec<(f32, Vec3)>,
    /// The cumulative probabilities of the bins (the last is 1).
    cdf: Vec<f32>,
}

/// Bins are drawn in proportion to the magnitude of their weights (|r| + |g| + |b|: the sRGB
/// weights of the spectrum's ends are negative in some channel), so no channel's weight
/// exceeds 1 over the least probable bin's share, and bins with no weight are never drawn.
static TABLE: LazyLock<Table> = LazyLock::new(|| {
    let weights = spectrum_rgb_weights(STEP_NM);
    let magnitude = |w: Vec3| f64::from(w.abs().element_sum());
    let total: f64 = weights.iter().map(|&(_, w)| magnitude(w)).sum();
    let mut running = 0.0;
    let mut cdf = Vec::with_capacity(weights.len());
    let mut bins = Vec::with_capacity(weights.len());
    for &(nm, w) in &weights {
        let p = magnitude(w) / total;
        running += p;
        cdf.push(running as f32);
        let weight = if p > 0.0 {
            (w.as_dvec3() / p).as_vec3()
        } else {
            Vec3::ZERO
        };
        bins.push((nm as f32, weight));
    }
    if let Some(last) = cdf.last_mut() {
        *last = 1.0;
    }
    Table { bins, cdf }
});

impl Wavelength {
    /// The wavelength of the number `u` in [0, 1): stratified numbers give stratified
    /// wavelengths (the bins in the cumulative order, each bin's share spread over its width).
    pub fn draw(u: f32) -> Self {
        let table = &*TABLE;
        let i = table
            .cdf
            .partition_point(|&c| c <= u)
            .min(table.cdf.len() - 1);
        let below = if i == 0 { 0.0 } else { table.cdf[i - 1] };
        let share = table.cdf[i] - below;
        let within = if share > 0.0 {
            ((u - below) / share).clamp(0.0, 1.0)
        } else {
            0.5
        };
        let (centre, weight) = table.bins[i];
        Self {
            nm: centre + (within - 0.5) * STEP_NM as f32,
            weight,
        }
    }
}

/// The index of refraction at `nm` of a Cauchy glass `index + b / nm^2` with `b` in nm^2
/// (LuxRender's `cauchyb`, given in um^2, times 10^6; [`CAUCHY_B_PER_UM2`]).
pub fn cauchy_index(index: f32, b_nm2: f32, nm: f32) -> f32 {
    index + b_nm2 / (nm * nm)
}

/// `cauchyb` in um^2 to the nm^2 of [`cauchy_index`].
pub const CAUCHY_B_PER_UM2: f32 = 1e6;

/// LuxRender's spectral range in nm (its `WAVELENGTH_START` and `WAVELENGTH_END`): a
/// dispersive fresnel texture's index, where a path has not taken one wavelength, is its mean
/// over this range.
pub const LUX_SPECTRUM_NM: (f32, f32) = (380.0, 720.0);

/// A real index of refraction that varies with wavelength: what LuxRender's dielectric fresnel
/// textures (`cauchy`, `abbe`, `sellmeier`, and the tabulated `sopra` and `luxpop` data) give
/// a volume's `fresnel`.
#[derive(Clone, Debug, PartialEq)]
pub enum IndexCurve {
    /// `a + b / nm^2`, `b` in nm^2.
    Cauchy { a: f32, b: f32 },
    /// `sqrt(a + sum of b nm^2 / (nm^2 - c))` over the terms `(b, c)`, `c` in nm^2.
    Sellmeier { a: f32, terms: Vec<(f32, f32)> },
    /// Linear interpolation between `(nm, n)` samples sorted by wavelength, held flat beyond
    /// either end.
    Table(Vec<(f32, f32)>),
}

impl IndexCurve {
    /// The index at `nm`.
    pub fn at(&self, nm: f32) -> f32 {
        match self {
            Self::Cauchy { a, b } => cauchy_index(*a, *b, nm),
            Self::Sellmeier { a, terms } => {
                let nm2 = nm * nm;
                let square = terms
                    .iter()
                    .fold(*a, |sum, &(b, c)| sum + b * nm2 / (nm2 - c));
                libm::sqrtf(square)
            }
            Self::Table(samples) => interpolate(samples, nm),
        }
    }

    /// LuxRender's index of the texture where a path has not taken one wavelength (its
    /// texture's `Y()`): the mean over [`LUX_SPECTRUM_NM`], exactly for Cauchy's formula (the
    /// mean of 1 / nm^2 over the range is one over the product of its ends), and for the others
    /// over the range's whole nanometres, as LuxRender sums Sellmeier's.
    pub fn mean(&self) -> f32 {
        let (start, end) = LUX_SPECTRUM_NM;
        match self {
            Self::Cauchy { a, b } => a + b / (start * end),
            _ => {
                let nms = start as u32..end as u32;
                let count = nms.len() as f64;
                let sum: f64 = nms.map(|nm| f64::from(self.at(nm as f32))).sum();
                (sum / count) as f32
            }
        }
    }

    /// Whether the index changes with wavelength (a Cauchy B of 0, or a table of one index,
    /// does not).
    pub fn varies(&self) -> bool {
        match self {
            Self::Cauchy { b, .. } => *b != 0.0,
            Self::Sellmeier { terms, .. } => terms.iter().any(|&(b, _)| b != 0.0),
            Self::Table(samples) => samples.windows(2).any(|w| w[0].1 != w[1].1),
        }
    }
}

/// Linear interpolation of `(x, y)` samples sorted by x at `x`, held flat beyond either end.
fn interpolate(samples: &[(f32, f32)], x: f32) -> f32 {
    let i = samples.partition_point(|s| s.0 < x);
    match (samples.get(i.wrapping_sub(1)), samples.get(i)) {
        (Some(&(x0, y0)), Some(&(x1, y1))) if x1 > x0 => y0 + (y1 - y0) * ((x - x0) / (x1 - x0)),
        (_, Some(&(_, y))) | (Some(&(_, y)), None) => y,
        (None, None) => 1.0,
    }
}

/// The most Sellmeier terms [`Dispersion::Sellmeier`] holds (the usual formula's three); a
/// curve of more is tabulated.
pub const SELLMEIER_TERMS: usize = 3;
/// [`Dispersion::Table`]'s first wavelength and spacing (nm), and its entries: every 20 nm over
/// the wavelengths [`Wavelength::draw`] gives.
pub const TABLE_FIRST_NM: f32 = 380.0;
pub const TABLE_STEP_NM: f32 = 20.0;
pub const TABLE_KNOTS: usize = 21;

/// How a dielectric interface's relative index (inside over outside) depends on the wavelength:
/// plain data a BxDF carries, built once per material and shape.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Dispersion {
    None,
    /// glass's `cauchyb` (here in nm^2): the interface's own index plus `b / nm^2`.
    CauchyB(f32),
    /// `a + b / nm^2` (glass2 between a Cauchy volume and one of constant index).
    Cauchy {
        a: f32,
        b: f32,
    },
    /// `sqrt(a + sum of b nm^2 / (nm^2 - c))` (glass2 between a Sellmeier volume of at most
    /// [`SELLMEIER_TERMS`] terms, unused ones 0, and one of constant index).
    Sellmeier {
        a: f32,
        b: [f32; SELLMEIER_TERMS],
        c: [f32; SELLMEIER_TERMS],
    },
    /// The index every [`TABLE_STEP_NM`] from [`TABLE_FIRST_NM`], interpolated linearly and
    /// held flat beyond the ends (glass2 between two volumes whose indices both vary, or one
    /// tabulated).
    Table([f32; TABLE_KNOTS]),
}

impl Dispersion {
    /// Whether the index changes with wavelength.
    pub fn varies(&self) -> bool {
        match self {
            Self::None => false,
            Self::CauchyB(b) => *b != 0.0,
            Self::Cauchy { b, .. } => *b != 0.0,
            Self::Sellmeier { b, .. } => b.iter().any(|&b| b != 0.0),
            Self::Table(n) => n.iter().any(|&v| v != n[0]),
        }
    }

    /// The relative index at `nm` of an interface whose index, where no wavelength is taken, is
    /// `eta`.
    pub fn index(&self, eta: f32, nm: f32) -> f32 {
        match self {
            Self::None => eta,
            Self::CauchyB(b) => cauchy_index(eta, *b, nm),
            Self::Cauchy { a, b } => cauchy_index(*a, *b, nm),
            Self::Sellmeier { a, b, c } => {
                let nm2 = nm * nm;
                let square =
                    (0..SELLMEIER_TERMS).fold(*a, |sum, i| sum + b[i] * nm2 / (nm2 - c[i]));
                libm::sqrtf(square)
            }
            Self::Table(n) => {
                let t =
                    ((nm - TABLE_FIRST_NM) / TABLE_STEP_NM).clamp(0.0, (TABLE_KNOTS - 1) as f32);
                let i = (t as usize).min(TABLE_KNOTS - 2);
                n[i] + (n[i + 1] - n[i]) * (t - i as f32)
            }
        }
    }

    /// The relative index of an interface between volumes of indices `interior` and
    /// `exterior`: each its index where no wavelength is taken and, when it varies with
    /// wavelength, its curve. None when neither varies; the exact formula when one side is
    /// constant and the other Cauchy's or Sellmeier's (of at most [`SELLMEIER_TERMS`] terms);
    /// a table of the ratio otherwise.
    pub fn between(
        interior: (f32, Option<&IndexCurve>),
        exterior: (f32, Option<&IndexCurve>),
    ) -> Self {
        let interior = (interior.0, interior.1.filter(|c| c.varies()));
        let exterior = (exterior.0, exterior.1.filter(|c| c.varies()));
        match (interior.1, exterior) {
            (None, (_, None)) => Self::None,
            (Some(IndexCurve::Cauchy { a, b }), (outside, None)) => Self::Cauchy {
                a: a / outside,
                b: b / outside,
            },
            (Some(IndexCurve::Sellmeier { a, terms }), (outside, None))
                if terms.len() <= SELLMEIER_TERMS =>
            {
                let square = outside * outside;
                let (mut bs, mut cs) = ([0.0; SELLMEIER_TERMS], [0.0; SELLMEIER_TERMS]);
                for (i, &(b, c)) in terms.iter().enumerate() {
                    bs[i] = b / square;
                    cs[i] = c;
                }
                Self::Sellmeier {
                    a: a / square,
                    b: bs,
                    c: cs,
                }
            }
            _ => {
                let side =
                    |(n, curve): (f32, Option<&IndexCurve>), nm: f32| curve.map_or(n, |c| c.at(nm));
                Self::Table(std::array::from_fn(|k| {
                    let nm = TABLE_FIRST_NM + k as f32 * TABLE_STEP_NM;
                    side(interior, nm) / side(exterior, nm)
                }))
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Stratified numbers' mean weight: white, whatever the channel.
    #[test]
    fn weights_average_to_white() {
        let n = 1 << 16;
        let sum: glam::DVec3 = (0..n)
            .map(|i| {
                let u = (i as f32 + 0.5) / n as f32;
                Wavelength::draw(u).weight.as_dvec3()
            })
            .sum();
        let mean = sum / f64::from(n);
        for c in mean.to_array() {
            assert!((c - 1.0).abs() < 2e-3, "mean weight {mean:?}");
        }
    }

    #[test]
    fn draws_span_the_spectrum_in_order() {
        let first = Wavelength::draw(0.0).nm;
        let last = Wavelength::draw(0.999_999).nm;
        assert!(first < 400.0 && last > 680.0, "{first} .. {last}");
        let mut prev = first;
        for i in 1..1000 {
            let nm = Wavelength::draw(i as f32 / 1000.0).nm;
            assert!(nm >= prev, "{nm} after {prev}");
            prev = nm;
        }
        // Blue light draws blue weight, red light red.
        let blue = Wavelength::draw(0.1).weight;
        let red = Wavelength::draw(0.9).weight;
        assert!(blue.z > blue.x && red.x > red.z, "{blue} {red}");
    }

    /// An interface's relative index is its two sides' ratio at every wavelength: exactly the
    /// formula of a Cauchy or Sellmeier inside over a constant outside (Cauchy over vacuum has
    /// the bits of glass's cauchyb), the ratio at the table's entries and within 3e-4 between
    /// them for two dispersive sides; none where neither side varies.
    #[test]
    fn the_relative_index_is_the_ratio_of_the_sides() {
        let glass = IndexCurve::Cauchy {
            a: 1.5,
            b: 0.02 * CAUCHY_B_PER_UM2,
        };
        let bk7 = IndexCurve::Sellmeier {
            a: 1.0,
            terms: vec![
                (1.039_612, 6_000.7),
                (0.231_792, 20_017.9),
                (1.010_469, 1.035_6e8),
            ],
        };
        let gas = IndexCurve::Cauchy {
            a: 1.02,
            b: 0.002 * CAUCHY_B_PER_UM2,
        };
        let over_vacuum = Dispersion::between((1.57, Some(&glass)), (1.0, None));
        let sellmeier = Dispersion::between((1.52, Some(&bk7)), (1.33, None));
        let table = Dispersion::between((1.57, Some(&glass)), (1.03, Some(&gas)));
        assert!(
            matches!(sellmeier, Dispersion::Sellmeier { .. }),
            "{sellmeier:?}"
        );
        assert!(matches!(table, Dispersion::Table(_)), "{table:?}");
        for i in 0..=400 {
            let nm = 380.0 + i as f32;
            let cauchy_b = Dispersion::CauchyB(0.02 * CAUCHY_B_PER_UM2).index(1.5, nm);
            assert_eq!(
                over_vacuum.index(0.0, nm).to_bits(),
                cauchy_b.to_bits(),
                "{nm}"
            );
            let ratio = bk7.at(nm) / 1.33;
            assert!((sellmeier.index(0.0, nm) - ratio).abs() < 1e-6, "{nm}");
            let ratio = glass.at(nm) / gas.at(nm);
            let tolerance = if i % 20 == 0 { 1e-6 } else { 3e-4 };
            assert!((table.index(0.0, nm) - ratio).abs() < tolerance, "{nm}");
        }
        let constant = IndexCurve::Cauchy { a: 1.4, b: 0.0 };
        assert_eq!(
            Dispersion::between((1.4, Some(&constant)), (1.0, None)),
            Dispersion::None
        );
        assert!(!Dispersion::None.varies() && !Dispersion::CauchyB(0.0).varies());
        assert!(over_vacuum.varies() && sellmeier.varies() && table.varies());
    }

    /// A curve's index where no wavelength is taken is its mean over LuxRender's 380-720 nm.
    #[test]
    fn a_curves_mean_is_over_luxrenders_spectrum() {
        let cauchy = IndexCurve::Cauchy {
            a: 1.5,
            b: 0.0042 * CAUCHY_B_PER_UM2,
        };
        let table = IndexCurve::Table(vec![(400.0, 1.6), (700.0, 1.5)]);
        for curve in [cauchy, table] {
            let sum: f64 = (0..3400)
                .map(|i| f64::from(curve.at(380.0 + (i as f32 + 0.5) * 0.1)))
                .sum();
            let mean = sum / 3400.0;
            assert!(
                (f64::from(curve.mean()) - mean).abs() < 2e-4,
                "{curve:?}: {mean}"
            );
        }
    }

    #[test]
    fn cauchy_index_is_larger_for_blue() {
        let b = 0.00420 * CAUCHY_B_PER_UM2;
        let blue = cauchy_index(1.5, b, 450.0);
        let red = cauchy_index(1.5, b, 650.0);
        assert!((blue - 1.520_74).abs() < 1e-4 && (red - 1.509_94).abs() < 1e-4);
    }
}
