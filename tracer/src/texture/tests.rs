//! Texture tests.
