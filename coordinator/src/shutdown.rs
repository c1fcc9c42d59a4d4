//! Stopping a render or a server: a flag the caller of a render owns and the render polls
//! ([`Interrupt`], which `yat render` wires to Ctrl-C (SIGINT) and SIGTERM), the error of a
//! render it stopped ([`Interrupted`]), and a future a server awaits ([`signalled`]).

use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::Arc;

use anyhow::Context;
use tokio::signal::unix::SignalKind;

/// A flag the render loops poll: once set, the render stops, saving what it merged where it
/// can and saying what is lost. The caller owns it: [`Interrupt::install`] sets it on Ctrl-C and
/// SIGTERM, [`Interrupt::cancel`] from code; a default one is set by nothing else.
#[derive(Clone, Default)]
pub struct Interrupt {
    set: Arc<AtomicBool>,
    /// The number of the signal that set it; 0 when [`Interrupt::cancel`] did.
    signal: Arc<AtomicUsize>,
}

/// Exit status of a render stopped by a signal (128 + SIGINT, as shells report it).
pub const INTERRUPTED_EXIT_CODE: u8 = 130;

impl Interrupt {
    /// An interrupt Ctrl-C and SIGTERM set: the first signal stops the render, a second one
    /// ends the process at once.
    pub fn install() -> anyhow::Result<Self> {
        let interrupt = Self::default();
        for signal in [signal_hook::consts::SIGINT, signal_hook::consts::SIGTERM] {
            // Registered first, so it sees the flag as the previous signal left it.
            signal_hook::flag::register_conditional_shutdown(
                signal,
                i32::from(INTERRUPTED_EXIT_CODE),
                interrupt.set.clone(),
            )
            .context("cannot watch for Ctrl-C")?;
            // The signal's number before the flag, so whoever sees the flag sees its cause.
            signal_hook::flag::register_usize(signal, interrupt.signal.clone(), signal as usize)
                .context("cannot watch for Ctrl-C")?;
            signal_hook::flag::register(signal, interrupt.set.clone())
                .context("cannot watch for Ctrl-C")?;
        }
        Ok(interrupt)
    }

    /// Stops the render as a signal would, the caller its cause.
    pub fn cancel(&self) {
        self.set.store(true, Ordering::Relaxed);
    }

    pub fn is_set(&self) -> bool {
        self.set.load(Ordering::Relaxed)
    }

    /// The signal that set the flag, as a user knows it.
    pub fn cause(&self) -> &'static str {
        match self.signal.load(Ordering::Relaxed) as i32 {
            0 => "its caller",
            signal_hook::consts::SIGTERM => "SIGTERM",
            _ => "Ctrl-C (SIGINT)",
        }
    }
}

/// The error of a render its [`Interrupt`] stopped; `main` exits with [`INTERRUPTED_EXIT_CODE`]
/// on it.
#[derive(Debug, thiserror::Error)]
#[error("interrupted by {cause}; {kept}")]
pub struct Interrupted {
    /// The signal or the caller, as [`Interrupt::cause`] names it.
    pub cause: &'static str,
    /// What became of the samples merged before it.
    pub kept: String,
}

/// Resolves at the first Ctrl-C or SIGTERM: a server's cue to stop taking requests and finish
/// those under way.
pub async fn signalled() {
    let terminate = async {
        match tokio::signal::unix::signal(SignalKind::terminate()) {
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
