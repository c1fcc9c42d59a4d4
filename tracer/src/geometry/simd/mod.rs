//! The traversal's SIMD kernels and the choice among them at run time: AVX-512 or AVX2 where
//! the CPU has it, SSE (every x86-64) otherwise, plain scalar code on other architectures. All
//! compute the same bits (see `wide_node`), so the choice changes speed, never the image.

mod scalar;
#[cfg(target_arch = "x86_64")]
mod x86;

pub use scalar::Scalar;
#[cfg(target_arch = "x86_64")]
pub use x86::{Avx2, Avx512, Sse};

/// An instruction set the traversal can run on.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Isa {
    Scalar,
    Sse,
    Avx2,
    /// AVX-512 F and VL (the AVX2 kernel's arithmetic in functions compiled for AVX-512).
    Avx512,
}

impl Isa {
    /// The instruction sets this CPU runs, slowest first.
    pub fn available() -> Vec<Isa> {
        #[cfg(target_arch = "x86_64")]
        {
            // SSE2 is part of x86-64.
            let mut isas = vec![Isa::Scalar, Isa::Sse];
            if std::arch::is_x86_feature_detected!("avx2") {
                isas.push(Isa::Avx2);
                if std::arch::is_x86_feature_detected!("avx512f")
                    && std::arch::is_x86_feature_detected!("avx512vl")
                {
                    isas.push(Isa::Avx512);
                }
            }
            isas
        }
        #[cfg(not(target_arch = "x86_64"))]
        vec![Isa::Scalar]
    }

    /// The fastest instruction set this CPU runs.
    pub fn best() -> Isa {
        *Self::available().last().unwrap_or(&Isa::Scalar)
    }
}
