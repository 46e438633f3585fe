//! MCML 1.2's ASCII output (`.mco`, written by `WriteResult` in `mcmlio.c`), the parts compared.
//!
//! `ReferenceData` (`reference.rs`) holds the same quantities as statistics over runs.

use super::McmlError;

/// The totals and radial reflectance of one MCML run, converted to mm (per incident photon).
#[derive(Debug, Clone, PartialEq)]
pub struct McmlOutput {
    /// Specular reflectance at entry.
    pub specular: f64,
    /// Diffuse reflectance R_d (all escaping weight, every annulus).
    pub diffuse_reflectance: f64,
    /// Absorbed fraction A.
    pub absorbed: f64,
    /// Total transmittance T_t.
    pub transmittance: f64,
    /// Absorbed fraction per layer, top first (`A_l`, printed to 4 significant digits).
    pub absorbed_by_layer: Vec<f64>,
    /// R_d(r) per annulus, mm⁻² (MCML prints cm⁻²); the last annulus holds all weight beyond it.
    pub rd_r_per_mm2: Vec<f64>,
}

/// The numbers that start the lines after the line whose first word is `section`, until a line that
/// does not start with a number.
fn section(text: &str, name: &str) -> Result<Vec<f64>, McmlError> {
    let mut lines = text.lines();
    lines
        .by_ref()
        .find(|l| l.split_whitespace().next() == Some(name))
        .ok_or_else(|| McmlError::Output(format!("no section '{name}'")))?;
    Ok(lines
        .map_while(|l| l.split_whitespace().next()?.parse::<f64>().ok())
        .collect())
}

/// Parse an `.mco` file: the `RAT` totals, `A_l`, and `Rd_r` (cm⁻² → mm⁻²).
pub fn parse_mco(text: &str) -> Result<McmlOutput, McmlError> {
    let rat = section(text, "RAT")?;
    let [specular, diffuse_reflectance, absorbed, transmittance] = rat[..] else {
        return Err(McmlError::Output(format!(
            "RAT has {} values, expected 4",
            rat.len()
        )));
    };
    let rd_r_per_mm2: Vec<f64> = section(text, "Rd_r")?
        .into_iter()
        .map(|v| v * 0.01)
        .collect();
    if rd_r_per_mm2.is_empty() {
        return Err(McmlError::Output("Rd_r is empty".into()));
    }
    Ok(McmlOutput {
        specular,
        diffuse_reflectance,
        absorbed,
        transmittance,
        absorbed_by_layer: section(text, "A_l")?,
        rd_r_per_mm2,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The layout `mcmlio.c` writes (abridged: sections not read are left out).
    const SAMPLE: &str = "A1 \t# Version number of the file format.\n\n\
        RAT #Reflectance, absorption, transmission. \n\
        0.0277778      \t#Specular reflectance [-]\n\
        0.825574       \t#Diffuse reflectance [-]\n\
        0.145553       \t#Absorbed fraction [-]\n\
        0.00109453     \t#Transmittance [-]\n\n\
        A_l #Absorption as a function of layer. [-]\n      0.1456\n           0\n\n\
        Rd_r #Rd[0], [1],..Rd[nr-1]. [1/cm2]\n  0.0000E+00\n  1.0305E+02\n  2.9096E+04\n\n\
        Rd_a #Rd[0], [1],..Rd[na-1]. [sr-1]\n  1.1830E-01\n";

    #[test]
    fn reads_the_totals_and_converts_the_profile_to_mm() {
        let o = parse_mco(SAMPLE).unwrap();
        assert_eq!(o.specular, 0.0277778);
        assert_eq!(o.diffuse_reflectance, 0.825574);
        assert_eq!(o.absorbed, 0.145553);
        assert_eq!(o.transmittance, 0.00109453);
        assert_eq!(o.absorbed_by_layer, vec![0.1456, 0.0]);
        assert_eq!(o.rd_r_per_mm2.len(), 3);
        assert!((o.rd_r_per_mm2[1] - 1.0305).abs() < 1e-12);
    }

    #[test]
    fn a_missing_section_is_an_error_naming_it() {
        let e = parse_mco("RAT\n1\n2\n3\n4\n").unwrap_err();
        assert!(e.to_string().contains("Rd_r"), "{e}");
        assert!(parse_mco("RAT\n1\n2\n").is_err());
    }
}
