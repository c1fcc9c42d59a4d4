//! Multiple importance sampling's weight.

use crate::lanes::Lanes;

/// The power heuristic's weight of a sample drawn with density `pdf_a` against one of
/// `pdf_b`, in lanes (one lane for a path alone; the packets' weights are the same bits).
#[inline(always)]
pub(super) fn power_heuristic<L: Lanes>(pdf_a: L, pdf_b: L) -> L {
    let (a, b) = (pdf_a * pdf_a, pdf_b * pdf_b);
    let zero = L::splat(0.0);
    L::select(zero.lt(a + b), a / (a + b), zero)
}
