//! What can stop an export.

#[derive(Debug, thiserror::Error)]
pub enum ExportError {
    #[error("LuxCore cannot render this scene faithfully: {0}")]
    Unsupported(String),
    #[error("cannot write the PLY of shape \"{shape}\": {error}")]
    Ply {
        shape: String,
        error: std::io::Error,
    },
}
