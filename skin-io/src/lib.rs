//! File I/O for the `skin` workspace: outputs written whole or not at all with an ordinary file's
//! permissions ([`atomic`]), input files read within their size caps ([`input`]), and the
//! verified, size-bounded disk cache of built tables ([`cache`]).

pub mod atomic;
pub mod cache;
pub mod input;
