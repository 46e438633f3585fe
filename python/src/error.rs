//! The one exception of the package, and the error every binding returns before it becomes one.

use std::fmt::Display;

pyo3::create_exception!(
    spectral_skin,
    SkinError,
    pyo3::exceptions::PyValueError,
    "Bad input to spectral_skin: the message starts with the parameter's name and states its valid range."
);

/// A bad input: the Python parameter's name and what is wrong with it (the range included).
#[derive(Debug)]
pub struct Bad {
    name: String,
    message: String,
}

impl Bad {
    /// `name`'s value is wrong as `message` says.
    pub fn new(name: impl Into<String>, message: impl Display) -> Self {
        Self {
            name: name.into(),
            message: message.to_string(),
        }
    }
}

impl From<Bad> for pyo3::PyErr {
    fn from(b: Bad) -> Self {
        SkinError::new_err(format!("{}: {}", b.name, b.message))
    }
}

/// Result of a binding's pure-Rust part.
pub type Checked<T> = Result<T, Bad>;

/// Run `f` on rayon's global pool, or on a pool of `threads` workers in [1, 1024].
pub fn on_threads<T: Send>(threads: Option<usize>, f: impl FnOnce() -> T + Send) -> Checked<T> {
    match threads {
        None => Ok(f()),
        Some(n) if !(1..=1024).contains(&n) => {
            Err(Bad::new("threads", format!("{n} outside [1, 1024]")))
        }
        Some(n) => rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build()
            .map(|pool| pool.install(f))
            .map_err(|e| Bad::new("threads", e)),
    }
}
