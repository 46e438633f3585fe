//! A measured diffuse reflectance spectrum to fit: wavelengths in 400–700 nm, reflectance in [0, 1],
//! optional non-negative weights; parsed from CSV `lambda_nm,reflectance[,weight]`.

use super::error::FitError;

/// Shortest wavelength a fitted spectrum may contain, nm (the model's visible range).
pub const MIN_NM: f64 = 400.0;
/// Longest wavelength a fitted spectrum may contain, nm.
pub const MAX_NM: f64 = 700.0;
/// Fewest data points a spectrum fit accepts: one per fitted parameter (C_m, β_m, C_h).
pub const MIN_POINTS: usize = 3;
/// Most data points a spectrum fit accepts: one per 0.1 nm over [`MIN_NM`, `MAX_NM`]. Each point
/// costs a forward-model wavelength per evaluation, so this bounds the fit's run time.
pub const MAX_POINTS: usize = 3001;

/// Validated measured reflectance (the observable: per unit incident flux, specular excluded).
#[derive(Debug, Clone, PartialEq)]
pub struct MeasuredSpectrum {
    lambda_nm: Vec<f64>,
    reflectance: Vec<f64>,
    weights: Vec<f64>,
}

/// Which row a value came from, for error messages: a CSV line, or an index when built in code.
fn row_line(i: usize, lines: Option<&[usize]>) -> usize {
    lines.map_or(i + 1, |l| l[i])
}

impl MeasuredSpectrum {
    /// A spectrum from wavelengths (nm, strictly increasing, in [400, 700]), reflectances in [0, 1]
    /// and optional weights (finite, ≥ 0, not all zero; `None` = all 1). Errors report the
    /// 1-based row as `line`.
    pub fn new(
        lambda_nm: Vec<f64>,
        reflectance: Vec<f64>,
        weights: Option<Vec<f64>>,
    ) -> Result<Self, FitError> {
        Self::validated(lambda_nm, reflectance, weights, None)
    }

    fn validated(
        lambda_nm: Vec<f64>,
        reflectance: Vec<f64>,
        weights: Option<Vec<f64>>,
        lines: Option<&[usize]>,
    ) -> Result<Self, FitError> {
        let n = lambda_nm.len();
        if n > MAX_POINTS {
            return Err(FitError::TooMuchData {
                points: n,
                max: MAX_POINTS,
            });
        }
        let weights = weights.unwrap_or_else(|| vec![1.0; n]);
        if reflectance.len() != n || weights.len() != n {
            return Err(FitError::NotEnoughData(format!(
                "{n} wavelengths but {} reflectances and {} weights",
                reflectance.len(),
                weights.len()
            )));
        }
        for i in 0..n {
            let line = row_line(i, lines);
            let check = |column, value: f64, lo: f64, hi: f64, range| {
                if value.is_finite() && value >= lo && value <= hi {
                    Ok(())
                } else {
                    Err(FitError::Value {
                        line,
                        column,
                        value,
                        range,
                    })
                }
            };
            check("lambda_nm", lambda_nm[i], MIN_NM, MAX_NM, "[400, 700] nm")?;
            check("reflectance", reflectance[i], 0.0, 1.0, "[0, 1]")?;
            check("weight", weights[i], 0.0, f64::MAX, "[0, ∞)")?;
            if i > 0 && lambda_nm[i] <= lambda_nm[i - 1] {
                return Err(FitError::NotIncreasing {
                    line,
                    lambda_nm: lambda_nm[i],
                    previous_nm: lambda_nm[i - 1],
                });
            }
        }
        if n < MIN_POINTS {
            return Err(FitError::NotEnoughData(format!(
                "{n} data points; a spectrum fit needs at least {MIN_POINTS} (one per parameter C_m, β_m, C_h)"
            )));
        }
        if weights.iter().filter(|w| **w > 0.0).count() < MIN_POINTS {
            return Err(FitError::NotEnoughData(format!(
                "fewer than {MIN_POINTS} data points have a positive weight"
            )));
        }
        Ok(Self {
            lambda_nm,
            reflectance,
            weights,
        })
    }

    /// Parse CSV text: `#` comment lines and blank lines anywhere; a header line
    /// `lambda_nm,reflectance` or `lambda_nm,reflectance,weight` (case-insensitive) before the data;
    /// then one row per wavelength. Every error names its 1-based line.
    pub fn parse_csv(text: &str) -> Result<Self, FitError> {
        let mut columns: Option<usize> = None;
        let (mut lambda, mut refl, mut weight, mut lines) = (vec![], vec![], vec![], vec![]);
        // A UTF-8 byte-order mark (spreadsheet exports) is not part of the header.
        let text = text.strip_prefix('\u{feff}').unwrap_or(text);
        for (i, raw) in text.lines().enumerate() {
            let line = i + 1;
            let trimmed = raw.trim();
            if trimmed.is_empty() || trimmed.starts_with('#') {
                continue;
            }
            let fields: Vec<&str> = trimmed.split(',').map(str::trim).collect();
            let Some(expected) = columns else {
                let names: Vec<String> = fields.iter().map(|f| f.to_ascii_lowercase()).collect();
                columns = match names.iter().map(String::as_str).collect::<Vec<_>>()[..] {
                    ["lambda_nm", "reflectance"] => Some(2),
                    ["lambda_nm", "reflectance", "weight"] => Some(3),
                    _ => {
                        return Err(FitError::Header {
                            line,
                            found: skin_optics::echo::text(trimmed),
                        });
                    }
                };
                continue;
            };
            if fields.len() != expected {
                return Err(FitError::FieldCount {
                    line,
                    found: fields.len(),
                    expected,
                });
            }
            let number = |column, text: &str| -> Result<f64, FitError> {
                text.parse::<f64>()
                    .ok()
                    .filter(|v| v.is_finite())
                    .ok_or_else(|| FitError::Number {
                        line,
                        column,
                        text: skin_optics::echo::text(text),
                    })
            };
            if lambda.len() == MAX_POINTS {
                return Err(FitError::TooMuchData {
                    points: MAX_POINTS + 1,
                    max: MAX_POINTS,
                });
            }
            lambda.push(number("lambda_nm", fields[0])?);
            refl.push(number("reflectance", fields[1])?);
            if expected == 3 {
                weight.push(number("weight", fields[2])?);
            }
            lines.push(line);
        }
        if columns.is_none() {
            return Err(FitError::NotEnoughData(
                "no header line `lambda_nm,reflectance[,weight]` and no data".to_string(),
            ));
        }
        let weights = (columns == Some(3)).then_some(weight);
        Self::validated(lambda, refl, weights, Some(&lines))
    }

    /// Wavelengths, nm, strictly increasing.
    #[must_use]
    pub fn lambda_nm(&self) -> &[f64] {
        &self.lambda_nm
    }

    /// Measured reflectances, one per wavelength, in [0, 1].
    #[must_use]
    pub fn reflectance(&self) -> &[f64] {
        &self.reflectance
    }

    /// Least-squares weights, one per wavelength (all 1 when the CSV had no weight column).
    #[must_use]
    pub fn weights(&self) -> &[f64] {
        &self.weights
    }

    /// The weights divided by the largest, in [0, 1]: the same least-squares problem, but sums of
    /// weighted squares neither overflow (weights near 1e308) nor underflow (subnormal weights).
    #[must_use]
    pub fn relative_weights(&self) -> Vec<f64> {
        let max = self.weights.iter().copied().fold(0.0, f64::max);
        self.weights.iter().map(|w| w / max).collect()
    }

    /// Number of data points.
    #[must_use]
    pub fn len(&self) -> usize {
        self.lambda_nm.len()
    }

    /// Always false for a validated spectrum (it has at least [`MIN_POINTS`]).
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.lambda_nm.is_empty()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_comments_header_and_weights() {
        let csv = "# measured forearm\n\nlambda_nm,Reflectance,weight\n400,0.2,1\n# mid\n450, 0.3 ,2\n500,0.35,0\n550,0.4,1\n";
        let s = MeasuredSpectrum::parse_csv(csv).unwrap();
        assert_eq!(s.lambda_nm(), &[400.0, 450.0, 500.0, 550.0]);
        assert_eq!(s.reflectance(), &[0.2, 0.3, 0.35, 0.4]);
        assert_eq!(s.weights(), &[1.0, 2.0, 0.0, 1.0]);
        let s = MeasuredSpectrum::parse_csv("lambda_nm,reflectance\n400,0.1\n500,0.2\n600,0.3")
            .unwrap();
        assert_eq!(s.weights(), &[1.0; 3]);
    }

    fn err(csv: &str) -> FitError {
        MeasuredSpectrum::parse_csv(csv).unwrap_err()
    }

    #[test]
    fn each_bad_input_names_its_line() {
        assert_eq!(
            err("400,0.2\n500,0.3\n600,0.4\n"),
            FitError::Header {
                line: 1,
                found: "400,0.2".into()
            }
        );
        let h = "# c\nlambda_nm,reflectance\n";
        assert_eq!(
            err(&format!("{h}400,0.2\n450,abc\n")),
            FitError::Number {
                line: 4,
                column: "reflectance",
                text: "abc".into()
            }
        );
        assert_eq!(
            err(&format!("{h}400,0.2\n450,NaN\n")),
            FitError::Number {
                line: 4,
                column: "reflectance",
                text: "NaN".into()
            }
        );
        assert_eq!(
            err(&format!("{h}400,0.2,3\n")),
            FitError::FieldCount {
                line: 3,
                found: 3,
                expected: 2
            }
        );
        assert_eq!(
            err(&format!("{h}400,0.2\n500,0.3\n450,0.3\n600,0.3\n")),
            FitError::NotIncreasing {
                line: 5,
                lambda_nm: 450.0,
                previous_nm: 500.0
            }
        );
        assert_eq!(
            err(&format!("{h}400,0.2\n500,1.2\n600,0.3\n")),
            FitError::Value {
                line: 4,
                column: "reflectance",
                value: 1.2,
                range: "[0, 1]"
            }
        );
        assert_eq!(
            err(&format!("{h}380,0.2\n500,0.2\n600,0.3\n")),
            FitError::Value {
                line: 3,
                column: "lambda_nm",
                value: 380.0,
                range: "[400, 700] nm"
            }
        );
        assert!(matches!(
            err("lambda_nm,reflectance,weight\n400,0.2,-1\n500,0.2,1\n600,0.3,1\n"),
            FitError::Value {
                line: 2,
                column: "weight",
                ..
            }
        ));
        assert!(matches!(
            err(&format!("{h}400,0.2\n500,0.2\n")),
            FitError::NotEnoughData(_)
        ));
        assert!(matches!(err("# nothing\n"), FitError::NotEnoughData(_)));
        assert!(matches!(
            MeasuredSpectrum::new(vec![500.0; MAX_POINTS + 1], vec![0.5; MAX_POINTS + 1], None),
            Err(FitError::TooMuchData { .. })
        ));
        // Messages are one line and carry the line number.
        let msg = err(&format!("{h}400,0.2\n500,1.2\n600,0.3\n")).to_string();
        assert_eq!(msg, "line 4: reflectance = 1.2 outside [0, 1]");
    }
}

#[cfg(test)]
mod hostile {
    use super::*;

    #[test]
    fn csv_with_a_utf8_byte_order_mark_parses() {
        let s = MeasuredSpectrum::parse_csv(
            "\u{feff}lambda_nm,reflectance\n400,0.1\n500,0.2\n600,0.3\n",
        )
        .unwrap();
        assert_eq!(s.len(), 3);
    }

    #[test]
    fn spectrum_with_a_million_rows_is_refused_before_fitting() {
        let mut csv = String::from("lambda_nm,reflectance\n");
        for i in 0..1_000_000 {
            csv.push_str(&format!("{},0.3\n", 400.0 + 300.0 * f64::from(i) / 1e6));
        }
        let e = MeasuredSpectrum::parse_csv(&csv).unwrap_err();
        assert_eq!(
            e,
            FitError::TooMuchData {
                points: MAX_POINTS + 1,
                max: MAX_POINTS
            }
        );
        assert!(e.to_string().contains("3001"), "{e}");
    }

    #[test]
    fn degenerate_weights_become_relative_weights_of_one() {
        // Weights of 1e308 overflow a weight sum, 1e-320 underflow the weighted squares: both
        // must give the unweighted problem (every relative weight 1).
        for w in [1e308, 1e-320, f64::MAX] {
            let s = MeasuredSpectrum::new(
                vec![400.0, 500.0, 600.0],
                vec![0.1, 0.2, 0.3],
                Some(vec![w; 3]),
            )
            .unwrap();
            assert_eq!(s.relative_weights(), vec![1.0; 3], "{w}");
        }
        let s = MeasuredSpectrum::new(
            vec![400.0, 500.0, 600.0],
            vec![0.1, 0.2, 0.3],
            Some(vec![2.0, 1.0, 0.5]),
        )
        .unwrap();
        assert_eq!(s.relative_weights(), vec![1.0, 0.5, 0.25]);
    }

    #[test]
    fn long_fields_are_echoed_cut() {
        let junk = "x".repeat(10_000);
        let e = MeasuredSpectrum::parse_csv(&format!("lambda_nm,reflectance\n400,{junk}\n"))
            .unwrap_err();
        assert!(e.to_string().len() < 200, "{e}");
    }
}
