//! Why the lights of a scene could not be prepared: a file a light references (an environment
//! map) that cannot be read or decoded.

#[derive(Debug, thiserror::Error)]
pub enum LightError {
    #[error(transparent)]
    Asset(#[from] crate::assets::AssetError),
    #[error(transparent)]
    Decode(#[from] crate::image_io::DecodeError),
}
