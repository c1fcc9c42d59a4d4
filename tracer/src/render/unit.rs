//! What a unit of work is and what rendering it reports: the types the film, the unit plan and
//! every node share. A leaf: it imports nothing from the crate.

/// A tile of pixels x a range of sample indices.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct WorkUnit {
    /// Position in the plan; results are keyed by it.
    pub index: u32,
    pub x0: u32,
    pub y0: u32,
    pub x1: u32,
    pub y1: u32,
    pub sample_start: u32,
    pub sample_end: u32,
}

impl WorkUnit {
    pub fn pixel_count(&self) -> usize {
        ((self.x1 - self.x0) * (self.y1 - self.y0)) as usize
    }

    pub fn sample_count(&self) -> u64 {
        self.pixel_count() as u64 * u64::from(self.sample_end - self.sample_start)
    }
}

/// Counters a unit's render reports.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct UnitStats {
    pub samples: u64,
    pub rays: u64,
    /// NaN or infinite samples dropped instead of entering the film.
    pub dropped: u64,
}

impl std::ops::AddAssign for UnitStats {
    fn add_assign(&mut self, o: Self) {
        self.samples += o.samples;
        self.rays += o.rays;
        self.dropped += o.dropped;
    }
}
