//! SIGINT and SIGTERM during `trilux solve`: the first stops the shooting
//! loop between shots (`Solver::stop_when`), and the command writes the
//! solution so far, marked partial (stop reason `interrupted`), and its
//! statistics, then exits with 128 + the signal's number (130, 143): the
//! run did not complete, as a scheduler expects, but its files are whole.
//! A second signal takes the signal's default action at once. Only `solve`
//! catches them: a render or a bake stopped by a signal still leaves
//! nothing half-written.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

/// The signals caught and the flags they set.
pub struct Interrupt {
    /// Set by the first signal; the solver polls it.
    stop: Arc<AtomicBool>,
    /// The number of the signal that arrived (0: none).
    signal: Arc<AtomicUsize>,
}

impl Interrupt {
    /// Catches SIGINT and SIGTERM from now on (on Unix; elsewhere they
    /// keep their default action).
    pub fn catch() -> anyhow::Result<Self> {
        let it = Interrupt {
            stop: Arc::new(AtomicBool::new(false)),
            signal: Arc::new(AtomicUsize::new(0)),
        };
        #[cfg(unix)]
        for sig in [signal_hook::consts::SIGINT, signal_hook::consts::SIGTERM] {
            use anyhow::Context;
            use signal_hook::flag;
            // The order matters: the default action is armed by the first
            // signal's flag, so it runs on the second only.
            let context = || format!("cannot catch signal {sig}");
            flag::register_conditional_default(sig, Arc::clone(&it.stop)).with_context(context)?;
            flag::register(sig, Arc::clone(&it.stop)).with_context(context)?;
            let number = usize::try_from(sig).unwrap_or(0);
            flag::register_usize(sig, Arc::clone(&it.signal), number).with_context(context)?;
        }
        Ok(it)
    }

    /// The flag the solver stops on.
    pub fn flag(&self) -> Arc<AtomicBool> {
        Arc::clone(&self.stop)
    }

    /// The exit status after a signal: 128 + its number; `None` when no
    /// signal arrived.
    pub fn status(&self) -> Option<u8> {
        match self.signal.load(Ordering::SeqCst) {
            0 => None,
            n => Some(u8::try_from(128 + n).unwrap_or(u8::MAX)),
        }
    }
}
