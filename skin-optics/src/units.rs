//! Wavelength, the one validated unit type of the optics crate (nm).

use crate::error::{OpticsError, check_range};

/// A wavelength in nanometres, guaranteed to lie inside the tabulated range [250, 1000] nm
/// of the hemoglobin data, so every chromophore function is defined for it.
#[derive(Debug, Clone, Copy, PartialEq, PartialOrd)]
pub struct Wavelength(f64);

impl Wavelength {
    /// Shortest supported wavelength, nm (start of Prahl's hemoglobin table).
    pub const MIN_NM: f64 = 250.0;
    /// Longest supported wavelength, nm (end of Prahl's hemoglobin table).
    pub const MAX_NM: f64 = 1000.0;

    /// A wavelength from nanometres; outside [250, 1000] nm is an error, not an extrapolation.
    pub fn new(nm: f64) -> Result<Self, OpticsError> {
        check_range(
            "wavelength (nm)",
            nm,
            Self::MIN_NM,
            Self::MAX_NM,
            "[250, 1000] nm",
        )
        .map(Self)
    }

    /// The wavelength in nanometres.
    #[must_use]
    pub fn nm(self) -> f64 {
        self.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn accepts_the_closed_table_range() {
        assert_eq!(Wavelength::new(250.0).unwrap().nm(), 250.0);
        assert_eq!(Wavelength::new(1000.0).unwrap().nm(), 1000.0);
        assert_eq!(Wavelength::new(555.5).unwrap().nm(), 555.5);
    }

    #[test]
    fn rejects_outside_and_non_finite() {
        for nm in [249.999, 1000.001, 0.0, -500.0] {
            assert!(
                matches!(Wavelength::new(nm), Err(OpticsError::OutOfRange { name: "wavelength (nm)", value, .. }) if value == nm),
                "{nm}"
            );
        }
        for nm in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            assert!(matches!(
                Wavelength::new(nm),
                Err(OpticsError::NonFinite {
                    name: "wavelength (nm)",
                    ..
                })
            ));
        }
        let msg = Wavelength::new(100.0).unwrap_err().to_string();
        assert_eq!(msg, "wavelength (nm) = 100 outside [250, 1000] nm");
    }
}
