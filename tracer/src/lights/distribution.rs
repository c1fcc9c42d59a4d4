//! Piecewise-constant distributions for importance sampling (pbrt's Distribution1D and 2D).

use glam::Vec2;

/// The largest f32 below 1: keeps remapped sample values in [0, 1).
const ONE_MINUS_EPSILON: f32 = 1.0 - f32::EPSILON / 2.0;

/// A piecewise-constant density on [0, 1) with `func.len()` equal bins; also a discrete
/// distribution over the bins.
#[derive(Clone, Debug)]
pub(crate) struct Distribution1D {
    func: Vec<f32>,
    /// `cdf[0] = 0`, `cdf[n] = 1`.
    cdf: Vec<f32>,
    /// The integral of `func` over [0, 1].
    integral: f32,
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
        let cdf = sums.iter().map(|&s| (s / sum) as f32).collect();
        Self {
            func,
            cdf,
            integral: sum as f32,
        }
    }

    pub fn len(&self) -> usize {
        self.func.len()
    }

    /// The probability of bin `i` as a discrete choice.
    pub fn pmf(&self, i: usize) -> f32 {
        self.func
            .get(i)
            .map_or(0.0, |f| f / (self.integral * self.len() as f32))
    }

    /// The bin containing `u`, its probability, and `u` rescaled to [0, 1) within the bin.
    /// None for an empty distribution.
    pub fn sample_discrete(&self, u: f32) -> Option<(usize, f32, f32)> {
        if self.func.is_empty() {
            return None;
        }
        let i = self.find_bin(u);
        let width = self.cdf[i + 1] - self.cdf[i];
        let u_remapped = ((u - self.cdf[i]) / width).clamp(0.0, ONE_MINUS_EPSILON);
        Some((i, self.pmf(i), u_remapped))
    }

    /// A point in [0, 1), its density, and its bin. None for an empty distribution.
    pub fn sample_continuous(&self, u: f32) -> Option<(f32, f32, usize)> {
        let (i, _, du) = self.sample_discrete(u)?;
        let x = ((i as f32 + du) / self.len() as f32).min(ONE_MINUS_EPSILON);
        Some((x, self.func[i] / self.integral, i))
    }

    /// The density of `sample_continuous` at `x` in [0, 1].
    pub fn pdf(&self, x: f32) -> f32 {
        let n = self.len();
        if n == 0 {
            return 0.0;
        }
        let i = ((x * n as f32) as usize).min(n - 1);
        self.func[i] / self.integral
    }

    /// The last bin whose start is at or below `u`: bins of zero width are never chosen.
    fn find_bin(&self, u: f32) -> usize {
        let starts_at_or_below = self.cdf.partition_point(|&c| c <= u);
        starts_at_or_below.saturating_sub(1).min(self.len() - 1)
    }
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
