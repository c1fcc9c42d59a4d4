//! Piecewise-constant distributions for importance sampling (pbrt's Distribution1D and 2D).

use glam::Vec2;

/// The largest f32 below 1: keeps remapped sample values in [0, 1).
const ONE_MINUS_EPSILON: f32 = 1.0 - f32::EPSILON / 2.0;

/// A piecewise-constant density on [0, 1) with `len()` equal bins; also a discrete
/// distribution over the bins.
#[derive(Clone, Debug)]
pub(crate) struct Distribution1D {
    /// One per bin, and a last one holding only `cdf = 1`. What a sample reads of a bin sits
    /// in one record, so one cache line: the rows of a large environment map are sampled at
    /// random, and three separate tables cost three cache misses per sample.
    bins: Vec<Bin>,
    /// The integral of the function over [0, 1].
    integral: f32,
}

#[derive(Clone, Copy, Debug)]
struct Bin {
    /// Where the bin starts in the cumulative distribution.
    cdf: f32,
    func: f32,
    /// The bin of u = k / len for the record k: a sample searches only the bins between the
    /// two bucket ends around it instead of the whole table (Chen and Asau's guide table).
    guide: u32,
}

impl Distribution1D {
    /// Negative and non-finite values count as zero; an all-zero (or empty) function gives the
    /// uniform distribution.
    pub fn new(func: Vec<f32>) -> Self {
        let mut func: Vec<f32> = func
            .into_iter()
            .map(|f| if f.is_finite() { f.max(0.0) } else { 0.0 })
            .collect();
        let n = func.len().max(1) as f64;
        // Accumulate in f64: a million-triangle table would lose the small bins in f32.
        let mut sums = Vec::with_capacity(func.len() + 1);
        let mut sum = 0.0f64;
        sums.push(0.0);
        for &f in &func {
            sum += f64::from(f) / n;
            sums.push(sum);
        }
        if sum <= 0.0 {
            func.iter_mut().for_each(|f| *f = 1.0);
            sums = (0..=func.len()).map(|i| i as f64 / n).collect();
            sum = 1.0;
        }
        let cdf: Vec<f32> = sums.iter().map(|&s| (s / sum) as f32).collect();
        let bins = cdf
            .iter()
            .zip(func.iter().chain([&0.0]))
            .zip(guide_table(&cdf))
            .map(|((&cdf, &func), guide)| Bin { cdf, func, guide })
            .collect();
        Self {
            bins,
            integral: sum as f32,
        }
    }

    pub fn len(&self) -> usize {
        self.bins.len() - 1
    }

    /// The probability of bin `i` as a discrete choice.
    pub fn pmf(&self, i: usize) -> f32 {
        if i < self.len() {
            self.bins[i].func / (self.integral * self.len() as f32)
        } else {
            0.0
        }
    }

    /// The bin containing `u`, its probability, and `u` rescaled to [0, 1) within the bin.
    /// None for an empty distribution.
    pub fn sample_discrete(&self, u: f32) -> Option<(usize, f32, f32)> {
        if self.len() == 0 {
            return None;
        }
        let i = self.find_bin(u);
        let start = self.bins[i].cdf;
        let width = self.bins[i + 1].cdf - start;
        let u_remapped = ((u - start) / width).clamp(0.0, ONE_MINUS_EPSILON);
        Some((i, self.pmf(i), u_remapped))
    }

    /// A point in [0, 1), its density, and its bin. None for an empty distribution.
    pub fn sample_continuous(&self, u: f32) -> Option<(f32, f32, usize)> {
        let (i, _, du) = self.sample_discrete(u)?;
        let x = ((i as f32 + du) / self.len() as f32).min(ONE_MINUS_EPSILON);
        Some((x, self.bins[i].func / self.integral, i))
    }

    /// The density of `sample_continuous` at `x` in [0, 1].
    pub fn pdf(&self, x: f32) -> f32 {
        let n = self.len();
        if n == 0 {
            return 0.0;
        }
        let i = ((x * n as f32) as usize).min(n - 1);
        self.bins[i].func / self.integral
    }

    /// The last bin whose start is at or below `u`: bins of zero width are never chosen.
    fn find_bin(&self, u: f32) -> usize {
        let n = self.len();
        let k = ((u * n as f32) as usize).min(n - 1);
        let (lo, hi) = (self.bins[k].guide as usize, self.bins[k + 1].guide as usize);
        let i = lo + self.bins[lo + 1..=hi].partition_point(|b| b.cdf <= u);
        // Rounding in u * n can pick a neighbouring bucket: check, and search it all.
        if self.bins[i].cdf <= u && (i + 1 == n || self.bins[i + 1].cdf > u) {
            i
        } else {
            last_bin_at_or_below(&self.bins, u)
        }
    }
}

fn last_bin_at_or_below(bins: &[Bin], u: f32) -> usize {
    bins.partition_point(|b| b.cdf <= u)
        .saturating_sub(1)
        .min(bins.len() - 2)
}

/// For each entry of `cdf`, the last bin starting at or below k / bins (the last bin for the
/// end entry).
fn guide_table(cdf: &[f32]) -> Vec<u32> {
    let bins = cdf.len() - 1;
    let mut guide = Vec::with_capacity(bins + 1);
    let mut i = 0;
    for k in 0..bins {
        let u = k as f32 / bins as f32;
        while i + 1 < bins && cdf[i + 1] <= u {
            i += 1;
        }
        guide.push(i as u32);
    }
    guide.push(bins.saturating_sub(1) as u32);
    guide
}

/// A piecewise-constant density on [0, 1)^2 over a `width` x `height` grid of cells, sampled
/// by choosing a row from the marginal and then a column from the row's conditional.
#[derive(Clone, Debug)]
pub(crate) struct Distribution2D {
    rows: Vec<Distribution1D>,
    marginal: Distribution1D,
}

impl Distribution2D {
    /// `func` holds `height` rows of `width` values, row 0 at v = 0.
    pub fn new(func: &[f32], width: usize, height: usize) -> Self {
        let rows: Vec<&[f32]> = func.chunks_exact(width).take(height).collect();
        // From the rows' own sums: an all-zero row samples uniformly but must weigh nothing.
        let marginal = Distribution1D::new(
            rows.iter()
                .map(|row| row.iter().map(|&f| f.max(0.0)).sum::<f32>() / width as f32)
                .collect(),
        );
        let rows = rows
            .into_iter()
            .map(|row| Distribution1D::new(row.to_vec()))
            .collect();
        Self { rows, marginal }
    }

    /// A point in [0, 1)^2 (x along the row, y across rows) and its density.
    pub fn sample(&self, u: Vec2) -> Option<(Vec2, f32)> {
        let (y, pdf_y, row) = self.marginal.sample_continuous(u.y)?;
        let (x, pdf_x, _) = self.rows[row].sample_continuous(u.x)?;
        Some((Vec2::new(x, y), pdf_x * pdf_y))
    }

    pub fn pdf(&self, p: Vec2) -> f32 {
        let height = self.rows.len();
        if height == 0 {
            return 0.0;
        }
        let row = ((p.y * height as f32) as usize).min(height - 1);
        self.rows[row].pdf(p.x) * self.marginal.pdf(p.y)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Bins of very different weight, runs of empty bins (inside and at both ends) and a
    /// single huge bin: the guided search must pick what a search of the whole table picks.
    #[test]
    fn guided_search_finds_the_bin_a_full_search_finds() {
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 40) as f32 / (1u64 << 24) as f32
        };
        let tables: Vec<Vec<f32>> = vec![
            vec![1.0],
            vec![0.0, 0.0, 5.0, 0.0],
            (0..1000).map(|_| next().powi(8)).collect(),
            (0..777)
                .map(|i| if (i / 50) % 2 == 0 { 0.0 } else { next() })
                .collect(),
            (0..300)
                .map(|i| if i == 150 { 1e6 } else { 1e-3 })
                .collect(),
        ];
        for func in tables {
            let d = Distribution1D::new(func);
            let probes = (0..20_000).map(|_| next()).chain(
                d.bins
                    .iter()
                    .flat_map(|b| [b.cdf, f32::from_bits(b.cdf.to_bits().saturating_sub(1))]),
            );
            for u in probes.filter(|u| (0.0..1.0).contains(u)) {
                let bin = d.find_bin(u);
                assert_eq!(bin, last_bin_at_or_below(&d.bins, u), "u = {u}");
                assert!(
                    d.bins[bin + 1].cdf > d.bins[bin].cdf,
                    "zero-width bin {bin} chosen"
                );
            }
        }
    }
}
