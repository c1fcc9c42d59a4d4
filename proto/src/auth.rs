//! The shared token: a worker started with one refuses every request that does not carry it in
//! the `authorization: Bearer <token>` metadata entry.

use std::sync::Arc;

use tonic::metadata::{Ascii, MetadataValue};
use tonic::service::Interceptor;
use tonic::{Request, Status};

const AUTHORIZATION: &str = "authorization";
const BEARER: &str = "Bearer ";

/// Server side: refuses requests without the expected token (`None` accepts every request).
#[derive(Clone)]
pub struct RequireToken {
    expected: Option<Arc<[u8]>>,
}

impl RequireToken {
    pub fn new(expected: Option<&str>) -> Self {
        Self {
            expected: expected.map(|t| t.as_bytes().into()),
        }
    }
}

impl Interceptor for RequireToken {
    fn call(&mut self, request: Request<()>) -> Result<Request<()>, Status> {
        let Some(expected) = &self.expected else {
            return Ok(request);
        };
        let given = request
            .metadata()
            .get(AUTHORIZATION)
            .and_then(|v| v.to_str().ok())
            .and_then(|v| v.strip_prefix(BEARER));
        match given {
            Some(token) if constant_time_eq(token.as_bytes(), expected) => Ok(request),
            Some(_) => Err(Status::unauthenticated(
                "authentication failed: wrong token",
            )),
            None => Err(Status::unauthenticated(
                "authentication failed: this worker requires a token (--token or YAT_TOKEN)",
            )),
        }
    }
}

/// Compares in time independent of where the bytes differ (`subtle`'s), so response timing
/// does not reveal a matching prefix (the HTTP servers' [`TokenDigest`] too). Only the length may show, which the token's strength does not rest on.
fn constant_time_eq(a: &[u8], b: &[u8]) -> bool {
    use subtle::ConstantTimeEq;
    a.ct_eq(b).into()
}

/// The token as the HTTP servers (the status page, a worker's `/metrics`) keep it: its SHA-256
/// digest in hex, which a cookie may carry in the token's place; every comparison in constant
/// time.
#[derive(Clone, Debug)]
pub struct TokenDigest(String);

impl TokenDigest {
    pub fn of(token: &str) -> Self {
        Self(crate::hash::sha256_hex(token.as_bytes()))
    }

    pub fn hex(&self) -> &str {
        &self.0
    }

    pub fn matches_token(&self, token: &str) -> bool {
        constant_time_eq(
            crate::hash::sha256_hex(token.as_bytes()).as_bytes(),
            self.0.as_bytes(),
        )
    }

    pub fn matches_digest(&self, digest: &str) -> bool {
        constant_time_eq(digest.as_bytes(), self.0.as_bytes())
    }

    /// Whether an `Authorization` header's value is `Bearer <the token>`.
    pub fn matches_bearer(&self, authorization: Option<&[u8]>) -> bool {
        authorization
            .and_then(|v| std::str::from_utf8(v).ok())
            .and_then(|v| v.strip_prefix(BEARER))
            .is_some_and(|token| self.matches_token(token))
    }
}

#[derive(Debug, thiserror::Error)]
#[error("the token must be printable ASCII")]
pub struct InvalidToken;

/// Client side: adds the token to every request (`None` adds nothing).
#[derive(Clone)]
pub struct AttachToken {
    header: Option<MetadataValue<Ascii>>,
}

impl AttachToken {
    pub fn new(token: Option<&str>) -> Result<Self, InvalidToken> {
        let header = token
            .map(|t| format!("{BEARER}{t}").parse().map_err(|_| InvalidToken))
            .transpose()?;
        Ok(Self { header })
    }
}

impl Interceptor for AttachToken {
    fn call(&mut self, mut request: Request<()>) -> Result<Request<()>, Status> {
        if let Some(header) = &self.header {
            request.metadata_mut().insert(AUTHORIZATION, header.clone());
        }
        Ok(request)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn check(worker: Option<&str>, client: Option<&str>) -> Result<(), Status> {
        let request = AttachToken::new(client).unwrap().call(Request::new(()))?;
        RequireToken::new(worker).call(request).map(drop)
    }

    #[test]
    fn token_is_required_and_compared() {
        assert!(check(Some("s3cret"), Some("s3cret")).is_ok());
        assert!(check(None, Some("anything")).is_ok());
        assert!(check(None, None).is_ok());
        for client in [Some("wrong"), Some("s3cre"), Some(""), None] {
            let status = check(Some("s3cret"), client).unwrap_err();
            assert_eq!(status.code(), tonic::Code::Unauthenticated);
            assert!(status.message().contains("authentication"));
        }
    }

    #[test]
    fn non_ascii_token_is_an_error() {
        assert!(AttachToken::new(Some("tok\nen")).is_err());
    }
}
