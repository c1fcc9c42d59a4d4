//! The deterministic sampler: a sample value for (pixel, sample index, dimension, seed).
