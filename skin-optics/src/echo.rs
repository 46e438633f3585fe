//! Values echoed back in error messages, kept short: numbers far from 1 in scientific notation
//! (1e308 is five characters, not 309 digits), long text cut with its length stated.

use std::fmt;

/// Longest text echoed whole, characters.
pub const MAX_ECHO_CHARS: usize = 40;

/// A number as an error message shows it: plain between 1e-4 and 1e7, scientific outside.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Num(pub f64);

impl fmt::Display for Num {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let v = self.0;
        let a = v.abs();
        if v == 0.0 || !v.is_finite() || (1e-4..1e7).contains(&a) {
            write!(f, "{v}")
        } else {
            write!(f, "{v:e}")
        }
    }
}

/// Text as an error message shows it: at most [`MAX_ECHO_CHARS`] characters, then `…` and the
/// full length.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Text<'a>(pub &'a str);

impl fmt::Display for Text<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let s = self.0;
        match s.char_indices().nth(MAX_ECHO_CHARS) {
            None => f.write_str(s),
            Some((cut, _)) => write!(f, "{}… ({} characters)", &s[..cut], s.chars().count()),
        }
    }
}

/// [`Text`] as an owned string (for error values that store the text they echo).
#[must_use]
pub fn text(s: &str) -> String {
    Text(s).to_string()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_1e308_is_echoed_in_scientific_notation() {
        assert_eq!(Num(1e308).to_string(), "1e308");
        assert_eq!(Num(-2.5e-9).to_string(), "-2.5e-9");
        assert_eq!(Num(0.25).to_string(), "0.25");
        assert_eq!(Num(550.0).to_string(), "550");
        assert_eq!(Num(f64::NEG_INFINITY).to_string(), "-inf");
    }

    #[test]
    fn a_ten_megabyte_string_is_echoed_cut() {
        let long = "a".repeat(10 << 20);
        let shown = Text(&long).to_string();
        assert!(shown.len() < 80, "{shown}");
        assert!(shown.ends_with("… (10485760 characters)"), "{shown}");
        assert_eq!(Text("light").to_string(), "light");
        // Cut on a character boundary.
        assert!(
            Text(&"é".repeat(100))
                .to_string()
                .starts_with(&"é".repeat(40))
        );
    }
}
