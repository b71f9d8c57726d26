//! Third-party parsers that panic on malformed input (the `dxf` crate does, e.g. on a header
//! date out of chrono's range, found by fuzzing): their panics become errors, quietly.
//!
//! [`catch_quietly`] runs a parser under `catch_unwind`; a panic hook installed once wraps the
//! previous hook and stays silent only while this thread is inside [`catch_quietly`], so every
//! other panic is reported as before. (This needs `panic = "unwind"`, the default profile.)

use std::cell::Cell;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::Once;
use thiserror::Error;

thread_local! {
    static QUIET: Cell<bool> = const { Cell::new(false) };
}
static HOOK: Once = Once::new();

/// A panic caught by [`catch_quietly`].
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum PanicError {
    /// The parser panicked with this message.
    #[error("{message}")]
    Panicked {
        /// The panic's message (`unknown failure` when it carries none).
        message: String,
    },
}

/// Runs `f`; a panic inside it is returned as its message instead of unwinding further.
pub fn catch_quietly<R>(f: impl FnOnce() -> R) -> Result<R, PanicError> {
    HOOK.call_once(|| {
        let previous = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            if !QUIET.with(Cell::get) {
                previous(info);
            }
        }));
    });
    let was = QUIET.with(|q| q.replace(true));
    let result = catch_unwind(AssertUnwindSafe(f));
    QUIET.with(|q| q.set(was));
    result.map_err(|payload| PanicError::Panicked {
        message: payload
            .downcast_ref::<&str>()
            .map(|s| s.to_string())
            .or_else(|| payload.downcast_ref::<String>().cloned())
            .unwrap_or_else(|| "unknown failure".into()),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_panic_becomes_its_message() {
        assert_eq!(catch_quietly(|| 3), Ok(3));
        let r: Result<(), PanicError> = catch_quietly(|| panic!("bad {}", 7));
        assert_eq!(
            r,
            Err(PanicError::Panicked {
                message: "bad 7".to_string()
            })
        );
        assert_eq!(r.unwrap_err().to_string(), "bad 7");
        assert_eq!(catch_quietly(|| 4), Ok(4));
    }
}
