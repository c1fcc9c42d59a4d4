//! Piecewise-constant distributions for importance sampling (pbrt's Distribution1D and 2D).

use glam::Vec2;

use crate::math::{bin_at, count_f32};

/// The largest f32 below 1: keeps remapped sample values in [0, 1).
pub(super) const ONE_MINUS_EPSILON: f32 = 1.0 - f32::EPSILON / 2.0;

/// Tables of at most this many bins are scanned, not searched: a scene's choice among a few
/// lights, or of a lamp's few triangles, is made at every path vertex, and a compare per bin
/// costs less there than the guide table's lookups and the search's branches.
pub(super) const SCANNED_BINS: usize = 8;

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

    /// Where each bin starts in the cumulative distribution, and a last value of 1.
    pub fn starts(&self) -> impl Iterator<Item = f32> + '_ {
        self.bins.iter().map(|b| b.cdf)
    }

    /// The probability of bin `i` as a discrete choice.
    pub fn pmf(&self, i: usize) -> f32 {
        if i < self.len() {
            self.bins[i].func / (self.integral * count_f32(self.len()))
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
        let x = ((count_f32(i) + du) / count_f32(self.len())).min(ONE_MINUS_EPSILON);
        Some((x, self.bins[i].func / self.integral, i))
    }

    /// The density of `sample_continuous` in bin `i` (in range).
    fn bin_pdf(&self, i: usize) -> f32 {
        self.bins[i].func / self.integral
    }

    /// The last bin whose start is at or below `u`: bins of zero width are never chosen.
    fn find_bin(&self, u: f32) -> usize {
        let n = self.len();
        if n <= SCANNED_BINS {
            // The starts rise with the index: the bins after the first that start at or below
            // `u` are the ones before it (NaN: none, bin 0, as the search below gives).
            return self.bins[1..n].iter().filter(|b| b.cdf <= u).count();
        }
        let k = bin_at(u * count_f32(n), n);
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
/// by choosing a row from the marginal and then a column from the row's alias table.
///
/// The rows are what a large environment map makes slow: a sample picks one at random, so
/// whatever it reads of the row is a cache miss. A row's inverse CDF needs two dependent reads
/// (the guide, then the search around it); its alias table needs one record, which holds the
/// densities of both bins it can pick. The marginal stays an inverse CDF (it is small and
/// stays in cache), so samples remain stratified across rows.
#[derive(Clone, Debug)]
pub(crate) struct Distribution2D {
    width: usize,
    /// `height` rows of `width` records, row 0 at v = 0.
    cells: Vec<AliasCell>,
    marginal: Distribution1D,
}

/// One column of a row's alias table (Walker's method, built by Vose's algorithm): a sample
/// landing in this column's slot keeps the column with probability `keep`, else takes `alias`.
/// Aligned so that a record never straddles two cache lines.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(16))]
struct AliasCell {
    keep: f32,
    alias: u32,
    /// The row's density (over x in [0, 1)) in this column and in the alias's.
    pdf: f32,
    alias_pdf: f32,
}

impl Distribution2D {
    /// `func` holds `height` rows of `width` values, row 0 at v = 0.
    pub fn new(func: &[f32], width: usize, height: usize) -> Self {
        let rows: Vec<&[f32]> = func.chunks_exact(width.max(1)).take(height).collect();
        // From the rows' own sums: an all-zero row samples uniformly but must weigh nothing.
        let marginal = Distribution1D::new(
            rows.iter()
                .map(|row| row.iter().map(|&f| f.max(0.0)).sum::<f32>() / width as f32)
                .collect(),
        );
        let cells = rows.into_iter().flat_map(alias_row).collect();
        Self {
            width: if height == 0 { 0 } else { width },
            cells,
            marginal,
        }
    }

    /// A point in [0, 1)^2 (x along the row, y across rows) and its density. `reading(row,
    /// column)` is called with the record about to be read, the column picked unless its
    /// alias is: a caller that reads its own data at the picked point can start loading it
    /// while this record's cache miss is under way.
    pub fn sample(&self, u: Vec2, reading: impl FnOnce(usize, usize)) -> Option<(Vec2, f32)> {
        if self.width == 0 {
            return None;
        }
        let (y, pdf_y, row) = self.marginal.sample_continuous(u.y)?;
        let n = self.width;
        let scaled = u.x.clamp(0.0, ONE_MINUS_EPSILON) * count_f32(n);
        let slot = bin_at(scaled, n);
        reading(row, slot);
        let (column, pdf_x, du) = self.cells[row * n + slot].pick(slot, scaled);
        let x = ((count_f32(column) + du) / count_f32(n)).min(ONE_MINUS_EPSILON);
        Some((Vec2::new(x, y), pdf_x * pdf_y))
    }

    /// Cells along a row and rows.
    pub fn cells(&self) -> (usize, usize) {
        (self.width, self.marginal.len())
    }

    /// The density in cell (`column`, `row`); 0 outside the grid.
    pub fn cell_pdf(&self, row: usize, column: usize) -> f32 {
        if column >= self.width || row >= self.marginal.len() {
            return 0.0;
        }
        self.cells[row * self.width + column].pdf * self.marginal.bin_pdf(row)
    }

    /// The density at `p`: that of the cell holding it.
    pub fn pdf(&self, p: Vec2) -> f32 {
        let height = self.marginal.len();
        if self.width == 0 || height == 0 {
            return 0.0;
        }
        self.cell_pdf(
            bin_at(p.y * count_f32(height), height),
            bin_at(p.x * count_f32(self.width), self.width),
        )
    }
}

impl AliasCell {
    /// What a sample at `scaled` (in [0, n) over the table's n slots) picks from the record of
    /// its slot `slot`: the column, its density over [0, 1), and where in the column it lands,
    /// in [0, 1).
    fn pick(self, slot: usize, scaled: f32) -> (usize, f32, f32) {
        let within = (scaled - count_f32(slot)).clamp(0.0, ONE_MINUS_EPSILON);
        let (column, pdf, du) = if within < self.keep {
            (slot, self.pdf, within / self.keep)
        } else {
            (
                self.alias as usize,
                self.alias_pdf,
                (within - self.keep) / (1.0 - self.keep),
            )
        };
        (column, pdf, du.clamp(0.0, ONE_MINUS_EPSILON))
    }
}

/// Discrete distributions of `len` entries each, stored one after another, each an alias
/// table (one record read per sample).
#[derive(Clone, Debug)]
pub(crate) struct AliasTables {
    len: usize,
    cells: Vec<AliasCell>,
}

impl AliasTables {
    /// `func` holds the tables' weights one table after another (a multiple of `len`, at least
    /// 1, entries). Weights as [`alias_row`] takes them: an all-zero table is uniform.
    pub fn new(func: &[f32], len: usize) -> Self {
        let len = len.max(1);
        Self {
            len,
            cells: func.chunks_exact(len).flat_map(alias_row).collect(),
        }
    }

    /// In table `table`: the entry `u` (in [0, 1)) picks, its probability times `len` (its
    /// density over [0, 1)), and `u` rescaled to [0, 1) within the entry. `reading(slot)` is
    /// called with the entry about to be read, the one picked unless its alias is (as
    /// [`Distribution2D::sample`]'s `reading`).
    pub fn sample(&self, table: usize, u: f32, reading: impl FnOnce(usize)) -> (usize, f32, f32) {
        let n = self.len;
        let scaled = u.clamp(0.0, ONE_MINUS_EPSILON) * count_f32(n);
        let slot = bin_at(scaled, n);
        reading(slot);
        self.cells[table * n + slot].pick(slot, scaled)
    }

    /// Entry `entry`'s probability in table `table`, times `len`.
    pub fn density(&self, table: usize, entry: usize) -> f32 {
        self.cells[table * self.len + entry].pdf
    }
}

/// A row's alias table. Densities as [`Distribution1D`] gives them: negative and non-finite
/// values count as zero, and an all-zero row is uniform. A column of zero weight is never
/// picked: its `keep` is 0 and its slot goes to a column that has weight.
fn alias_row(row: &[f32]) -> Vec<AliasCell> {
    let n = row.len();
    let mut weight: Vec<f64> = row
        .iter()
        .map(|&f| {
            if f.is_finite() {
                f64::from(f.max(0.0))
            } else {
                0.0
            }
        })
        .collect();
    let mut total: f64 = weight.iter().sum();
    if total <= 0.0 {
        weight.iter_mut().for_each(|w| *w = 1.0);
        total = n as f64;
    }
    // The density over [0, 1) is f / mean(f), as Distribution1D's func / integral.
    let pdf: Vec<f32> = weight
        .iter()
        .map(|&w| (w * n as f64 / total) as f32)
        .collect();
    // Each slot holds one unit of probability mass (times n); Vose's algorithm fills the slots
    // of light columns with mass from heavy ones.
    let mut mass: Vec<f64> = weight.iter().map(|&w| w * n as f64 / total).collect();
    let mut cells: Vec<AliasCell> = (0..n)
        .map(|i| AliasCell {
            keep: 1.0,
            alias: i as u32,
            pdf: pdf[i],
            alias_pdf: pdf[i],
        })
        .collect();
    let (mut light, mut heavy): (Vec<usize>, Vec<usize>) = (0..n).partition(|&i| mass[i] < 1.0);
    while let (Some(&l), Some(&h)) = (light.last(), heavy.last()) {
        light.pop();
        cells[l].keep = mass[l] as f32;
        cells[l].alias = h as u32;
        cells[l].alias_pdf = pdf[h];
        mass[h] -= 1.0 - mass[l];
        if mass[h] < 1.0 {
            heavy.pop();
            light.push(h);
        }
    }
    // What is left holds a whole slot up to rounding, and keeps it (keep = 1 from above); a
    // column of zero weight cannot be among it, as the slots of the heavy ones take all the
    // rest of the mass.
    for i in light {
        if weight[i] == 0.0 {
            // Unreachable up to rounding of the f64 sums; never let it be picked.
            let donor = weight.iter().position(|&w| w > 0.0).unwrap_or(i);
            cells[i].keep = 0.0;
            cells[i].alias = donor as u32;
            cells[i].alias_pdf = pdf[donor];
        }
    }
    cells
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Bins of very different weight, runs of empty bins (inside and at both ends) and a
    /// single huge bin: the guided search, and the scan of a small table, must pick what a
    /// search of the whole table picks.
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
            vec![3.0, 1.0],
            vec![0.0, 0.0, 5.0, 0.0],
            vec![0.0, 2.0, 0.0, 0.0, 1.0, 3.0, 0.0, 0.5],
            vec![0.0, 2.0, 0.0, 0.0, 1.0, 3.0, 0.0, 0.5, 0.0],
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

    /// A row's alias table picks each column with the probability its density gives, never a
    /// column of zero weight, spreads the samples evenly inside the column, and reports the
    /// density that `pdf` gives at the point. Over an even grid of u.x the counts are exact up
    /// to one sample per slot boundary.
    #[test]
    fn alias_rows_sample_their_density() {
        let row = [0.0, 3.0, 0.5, 0.0, 7.0, 1e-3, 2.5, 0.0, 0.0, 4.0];
        let rows = [row.to_vec(), vec![0.0; 10], vec![1.0; 10]].concat();
        let d = Distribution2D::new(&rows, 10, 3);
        let total: f32 = row.iter().sum();
        let m = 200_000;
        let mut counts = [0usize; 10];
        let mut within = [0.0f64; 10];
        // u.y = 0.1 lands in row 0, which holds most of the weight.
        for j in 0..m {
            let u = Vec2::new((j as f32 + 0.5) / m as f32, 0.1);
            let (p, density) = d.sample(u, |_, _| {}).expect("a sample");
            assert_eq!((p.y * 3.0) as usize, 0);
            assert_eq!(density, d.pdf(p), "at {p}");
            let column = (p.x * 10.0) as usize;
            counts[column] += 1;
            within[column] += f64::from(p.x * 10.0 - column as f32);
        }
        for (i, &f) in row.iter().enumerate() {
            let expected = f / total;
            let got = counts[i] as f32 / m as f32;
            assert!(
                (got - expected).abs() <= 20.0 / m as f32,
                "column {i}: {got} vs {expected}"
            );
            if f == 0.0 {
                assert_eq!(counts[i], 0, "zero-weight column {i} picked");
            } else if counts[i] > 1000 {
                let mean = within[i] / counts[i] as f64;
                assert!(
                    (mean - 0.5).abs() < 0.01,
                    "column {i}: mean position {mean}"
                );
            }
        }
        // The all-zero row is never chosen and the uniform one has density 1 along x.
        let marginal_zero = d.pdf(Vec2::new(0.5, 0.5));
        assert_eq!(marginal_zero, 0.0);
        let uniform = d.pdf(Vec2::new(0.37, 0.9));
        let row_weight = 1.0 / (total / 10.0 + 1.0);
        assert!((uniform - 3.0 * row_weight).abs() < 1e-5, "{uniform}");
    }
}
