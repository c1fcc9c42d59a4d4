//! The network flags both ends of a connection share, defined once so that `yat worker` and
//! `yat render` spell them alike: the token (`--token` / `YAT_TOKEN`), the worker's TLS
//! certificate and key, and the CA a coordinator trusts. Each side flattens the structs it
//! needs into its own arguments.

use std::path::{Path, PathBuf};

use tonic::transport::{Certificate, ClientTlsConfig, Identity};

/// `--token` / `YAT_TOKEN`: the shared secret (see [`crate::auth`]).
#[derive(clap::Args, Clone, Debug, Default)]
pub struct TokenFlag {
    /// The shared token: a worker refuses requests without it, a coordinator sends it.
    #[arg(long, env = "YAT_TOKEN", hide_env_values = true)]
    pub token: Option<String>,
}

/// A worker's TLS identity: `--tls-cert` and `--tls-key`, both or neither.
#[derive(clap::Args, Clone, Debug, Default)]
pub struct ServerTlsFlags {
    /// Serve TLS with this PEM certificate (chain).
    #[arg(long, requires = "tls_key")]
    pub tls_cert: Option<PathBuf>,
    /// The PEM private key of --tls-cert.
    #[arg(long, requires = "tls_cert")]
    pub tls_key: Option<PathBuf>,
}

impl ServerTlsFlags {
    /// The certificate and key to serve TLS with, read from their files; `None` without TLS.
    pub fn identity(&self) -> Result<Option<Identity>, ReadPemError> {
        match (&self.tls_cert, &self.tls_key) {
            (Some(cert), Some(key)) => Ok(Some(Identity::from_pem(read(cert)?, read(key)?))),
            _ => Ok(None),
        }
    }
}

/// What a coordinator trusts: `--tls-ca` and the optional `--tls-domain`.
#[derive(clap::Args, Clone, Debug, Default)]
pub struct ClientTlsFlags {
    /// Connect to the workers over TLS, trusting this PEM CA certificate.
    #[arg(long, value_name = "PEM")]
    pub tls_ca: Option<PathBuf>,
    /// The name the workers' certificates are issued to [default: the host of each address].
    #[arg(long, requires = "tls_ca")]
    pub tls_domain: Option<String>,
}

impl ClientTlsFlags {
    /// The TLS settings of connections to workers, the CA read from its file; `None` without
    /// TLS.
    pub fn config(&self) -> Result<Option<ClientTlsConfig>, ReadPemError> {
        let Some(ca) = &self.tls_ca else {
            return Ok(None);
        };
        let mut tls = ClientTlsConfig::new().ca_certificate(Certificate::from_pem(read(ca)?));
        if let Some(domain) = &self.tls_domain {
            tls = tls.domain_name(domain.clone());
        }
        Ok(Some(tls))
    }
}

/// A certificate or key file that cannot be read.
#[derive(Debug, thiserror::Error)]
#[error("cannot read {}", path.display())]
pub struct ReadPemError {
    path: PathBuf,
    source: std::io::Error,
}

fn read(path: &Path) -> Result<Vec<u8>, ReadPemError> {
    std::fs::read(path).map_err(|source| ReadPemError {
        path: path.to_path_buf(),
        source,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;

    #[derive(Parser)]
    struct Server {
        #[command(flatten)]
        token: TokenFlag,
        #[command(flatten)]
        tls: ServerTlsFlags,
    }

    #[derive(Parser)]
    struct Client {
        #[command(flatten)]
        token: TokenFlag,
        #[command(flatten)]
        tls: ClientTlsFlags,
    }

    #[test]
    fn tls_flags_come_in_pairs_and_name_the_unreadable_file() {
        assert!(Server::try_parse_from(["w", "--tls-cert", "c.pem"]).is_err());
        assert!(Client::try_parse_from(["c", "--tls-domain", "localhost"]).is_err());
        let server =
            Server::try_parse_from(["w", "--tls-cert", "/nowhere/c", "--tls-key", "k"]).unwrap();
        let error = server.tls.identity().unwrap_err();
        assert_eq!(error.to_string(), "cannot read /nowhere/c");
        let client = Client::try_parse_from(["c", "--token", "t"]).unwrap();
        assert_eq!(client.token.token.as_deref(), Some("t"));
        assert!(client.tls.config().unwrap().is_none());
    }
}
