//! Interrupt handling: Ctrl-C (SIGINT) and SIGTERM.

use tokio::signal::unix::{signal, SignalKind};

/// Resolves at the first Ctrl-C or SIGTERM: a server's cue to stop taking requests and finish
/// those under way.
pub async fn signalled() {
    let terminate = async {
        match signal(SignalKind::terminate()) {
            Ok(mut terminate) => {
                terminate.recv().await;
            }
            // Without a SIGTERM handler the signal keeps its default action: the process ends.
            Err(_) => std::future::pending().await,
        }
    };
    tokio::select! {
        _ = tokio::signal::ctrl_c() => {}
        _ = terminate => {}
    }
}
