//! BSDF tests.
