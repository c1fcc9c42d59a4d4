//! The layers a render's units may carry besides radiance and weight: per pixel, filter-weighted
//! sums of a value each camera sample gives, whose weighted mean is the pixel's value, as the
//! colour's is. Alpha: LuxRender's coverage of the camera ray (0 where it escapes to the
//! environment having met nothing but surfaces it crosses straight on, null surfaces and
//! architectural panes; 1 where it meets anything else). Which layers a render keeps is part of
//! its film frame, which every node derives from the scene and the settings alike, so a render
//! that keeps none has the buffers, wire bytes and checkpoint it always had. A leaf.

/// Which layers a render's units carry.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Layers {
    pub alpha: bool,
}

impl Layers {
    /// No layer: radiance and weight alone.
    pub const NONE: Self = Self { alpha: false };

    /// The f32 sums per pixel a unit's buffer holds for them (i64 in the film), in the order
    /// of [`LayerSample::values`].
    pub fn len(self) -> usize {
        usize::from(self.alpha)
    }

    pub fn is_empty(self) -> bool {
        self.len() == 0
    }
}

/// The most sums per pixel any set of layers has.
pub const MAX_LAYER_SUMS: usize = 1;

/// What one camera sample gives the layers.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LayerSample {
    /// 1 where the camera ray met something, 0 where it escaped.
    pub alpha: f32,
}

impl LayerSample {
    /// The sample's values of `layers`, in their order; the first `layers.len()` count.
    pub fn values(&self, layers: Layers) -> [f32; MAX_LAYER_SUMS] {
        let mut out = [0.0; MAX_LAYER_SUMS];
        let mut at = 0;
        if layers.alpha {
            out[at] = self.alpha;
            at += 1;
        }
        debug_assert_eq!(at, layers.len());
        out
    }
}
