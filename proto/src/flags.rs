//! The network flags both ends of a connection share, defined once so that `yat worker` and
//! `yat render` spell them alike: the token (`--token-file`, `YAT_TOKEN` or `--token`), the
//! worker's TLS certificate and key and the CA its clients' certificates must come from, and
//! the CA a coordinator trusts with the certificate it shows. Each side flattens the structs it
//! needs into its own arguments.

use std::io::Read;
use std::path::{Path, PathBuf};

use tonic::transport::{Certificate, ClientTlsConfig, Identity};

/// The longest token file read; a token is one short line.
const MAX_TOKEN_FILE_BYTES: u64 = 4096;

/// `--token-file` / `YAT_TOKEN` / `--token`: the shared secret (see [`crate::auth`]).
#[derive(clap::Args, Clone, Debug, Default)]
pub struct TokenFlag {
    /// The shared token: a worker refuses requests without it, a coordinator sends it. Every
    /// local user sees a command line (`ps`): prefer --token-file or YAT_TOKEN.
    #[arg(long, env = "YAT_TOKEN", hide_env_values = true)]
    pub token: Option<String>,
    /// Read the shared token from the first line of this file (a regular file; surrounding
    /// blanks trimmed). Wins over --token and YAT_TOKEN.
    #[arg(long, value_name = "PATH")]
    pub token_file: Option<PathBuf>,
}

impl TokenFlag {
    /// The token, read from `--token-file` if given, else `--token` / `YAT_TOKEN`.
    pub fn resolve(&self) -> Result<Option<String>, TokenFileError> {
        let Some(path) = &self.token_file else {
            return Ok(self.token.clone());
        };
        let error = |problem: String| TokenFileError {
            path: path.clone(),
            problem,
        };
        // Follows symbolic links (Kubernetes mounts secrets through them) to a regular file,
        // checked before opening: opening a FIFO would block.
        let metadata = std::fs::metadata(path).map_err(|e| error(e.to_string()))?;
        if !metadata.is_file() {
            return Err(error("not a regular file".into()));
        }
        let file = std::fs::File::open(path).map_err(|e| error(e.to_string()))?;
        let mut text = String::new();
        file.take(MAX_TOKEN_FILE_BYTES)
            .read_to_string(&mut text)
            .map_err(|e| error(e.to_string()))?;
        let token = text.lines().next().unwrap_or("").trim();
        if token.is_empty() {
            return Err(error("its first line is empty".into()));
        }
        Ok(Some(token.to_string()))
    }
}

/// A `--token-file` that does not hold a token.
#[derive(Debug, thiserror::Error)]
#[error("--token-file {}: {problem}", path.display())]
pub struct TokenFileError {
    path: PathBuf,
    problem: String,
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
    /// Accept only clients showing a certificate this PEM CA issued (TLS client
    /// authentication; needs --tls-cert).
    #[arg(long, value_name = "PEM", requires = "tls_cert")]
    pub tls_client_ca: Option<PathBuf>,
}

impl ServerTlsFlags {
    /// The certificate and key to serve TLS with, read from their files; `None` without TLS.
    pub fn identity(&self) -> Result<Option<Identity>, ReadPemError> {
        match (&self.tls_cert, &self.tls_key) {
            (Some(cert), Some(key)) => Ok(Some(Identity::from_pem(read(cert)?, read(key)?))),
            _ => Ok(None),
        }
    }

    /// The CA client certificates must come from; `None` without client authentication.
    pub fn client_ca(&self) -> Result<Option<Certificate>, ReadPemError> {
        let ca = self.tls_client_ca.as_deref().map(read).transpose()?;
        Ok(ca.map(Certificate::from_pem))
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
    /// Show the workers this PEM certificate (for workers started with --tls-client-ca).
    #[arg(long, value_name = "PEM", requires_all = ["tls_ca", "tls_client_key"])]
    pub tls_client_cert: Option<PathBuf>,
    /// The PEM private key of --tls-client-cert.
    #[arg(long, value_name = "PEM", requires = "tls_client_cert")]
    pub tls_client_key: Option<PathBuf>,
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
        if let (Some(cert), Some(key)) = (&self.tls_client_cert, &self.tls_client_key) {
            tls = tls.identity(Identity::from_pem(read(cert)?, read(key)?));
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
        assert!(Server::try_parse_from(["w", "--tls-client-ca", "ca.pem"]).is_err());
        assert!(Client::try_parse_from(["c", "--tls-ca", "a", "--tls-client-cert", "c"]).is_err());
        let server = Server::try_parse_from(["w"]).unwrap();
        assert!(server.tls.client_ca().unwrap().is_none());
    }

    #[test]
    fn a_token_file_gives_its_first_line_and_must_be_a_regular_file() {
        let dir = std::env::temp_dir().join(format!("yat-token-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let file = dir.join("token");
        std::fs::write(&file, "  s3cret \nsecond line\n").unwrap();
        let path = file.to_str().unwrap();
        let flags = Client::try_parse_from(["c", "--token", "other", "--token-file", path]);
        assert_eq!(
            flags.unwrap().token.resolve().unwrap().as_deref(),
            Some("s3cret")
        );
        std::fs::write(&file, "\n").unwrap();
        let flags = Client::try_parse_from(["c", "--token-file", path]).unwrap();
        assert!(flags
            .token
            .resolve()
            .unwrap_err()
            .to_string()
            .contains("empty"));
        let flags = Client::try_parse_from(["c", "--token-file", dir.to_str().unwrap()]).unwrap();
        let error = flags.token.resolve().unwrap_err().to_string();
        assert!(error.contains("not a regular file"), "{error}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
