//! Colours of measured spectra and of the models fitted to them (CIE 1931 2°, D65, CIELAB,
//! CIEDE2000 from `skin_optics`; docs/physics.md §12–§13), per record and per group and site, and
//! the fitted parameters that sit on a bound of their range.

use crate::measured::{RecordFit, quantile};
use skin_fit::Parameter;
use skin_optics::color::reflectance_to_xyz;
use skin_optics::lab::Lab;
use skin_optics::{GridSpectrum, WavelengthGrid};
use std::fmt::Write as _;

/// CIELAB (D65) of a reflectance sampled on an evenly spaced grid `lambda_nm`.
pub fn lab_of(lambda_nm: &[f64], reflectance: &[f64]) -> anyhow::Result<Lab> {
    let n = lambda_nm.len();
    anyhow::ensure!(n >= 2, "a colour needs at least two wavelengths");
    let step = (lambda_nm[n - 1] - lambda_nm[0]) / (n - 1) as f64;
    anyhow::ensure!(
        lambda_nm
            .iter()
            .enumerate()
            .all(|(i, &nm)| (nm - lambda_nm[0] - step * i as f64).abs() < 1e-9),
        "wavelengths are not evenly spaced"
    );
    let grid = WavelengthGrid::new(lambda_nm[0], lambda_nm[n - 1], step)?;
    let spectrum = GridSpectrum::new(grid, reflectance.to_vec())?;
    Ok(Lab::from_xyz(reflectance_to_xyz(&spectrum)))
}

/// Measured and fitted colour of one record (both as the instrument sees them).
#[derive(Debug, Clone, Copy)]
pub struct RecordColour {
    /// Colour of the measured spectrum.
    pub measured: Lab,
    /// Colour of the fitted model's spectrum at the same wavelengths.
    pub model: Lab,
}

impl RecordColour {
    /// CIEDE2000 between the two.
    #[must_use]
    pub fn delta_e(&self) -> f64 {
        self.measured.delta_e_2000(self.model)
    }
}

/// The colours of every fit.
pub fn record_colours(fits: &[RecordFit]) -> anyhow::Result<Vec<RecordColour>> {
    fits.iter()
        .map(|f| {
            let nm = f.record.spectrum.lambda_nm();
            Ok(RecordColour {
                measured: lab_of(nm, f.record.spectrum.reflectance())?,
                model: lab_of(nm, &f.fit.model)?,
            })
        })
        .collect()
}

/// The mean of CIELAB colours, coordinate by coordinate.
pub(crate) fn mean_lab(labs: impl Iterator<Item = Lab>) -> Lab {
    let (mut s, mut n) = ([0.0; 3], 0.0);
    for c in labs {
        s[0] += c.l;
        s[1] += c.a;
        s[2] += c.b;
        n += 1.0;
    }
    Lab {
        l: s[0] / n,
        a: s[1] / n,
        b: s[2] / n,
    }
}

/// Per group and site (in the order first met): the mean measured L*a*b* over its records (the
/// figure a study of skin colour publishes) and the mean of the fitted models' colours.
#[must_use]
pub fn group_colours(
    fits: &[RecordFit],
    colours: &[RecordColour],
) -> Vec<(String, usize, RecordColour)> {
    let mut keys: Vec<String> = Vec::new();
    for f in fits {
        let k = format!("{} {}", f.record.group, f.record.site);
        if !keys.contains(&k) {
            keys.push(k);
        }
    }
    keys.into_iter()
        .map(|k| {
            let members: Vec<&RecordColour> = fits
                .iter()
                .zip(colours)
                .filter(|(f, _)| format!("{} {}", f.record.group, f.record.site) == k)
                .map(|(_, c)| c)
                .collect();
            let c = RecordColour {
                measured: mean_lab(members.iter().map(|c| c.measured)),
                model: mean_lab(members.iter().map(|c| c.model)),
            };
            (k, members.len(), c)
        })
        .collect()
}

/// One summary line of the colour errors: per record and per group/site mean colour.
pub fn colour_summary(label: &str, fits: &[RecordFit]) -> anyhow::Result<String> {
    let colours = record_colours(fits)?;
    let de: Vec<f64> = colours.iter().map(RecordColour::delta_e).collect();
    let groups = group_colours(fits, &colours);
    let gde: Vec<f64> = groups.iter().map(|g| g.2.delta_e()).collect();
    let within = |v: &[f64]| v.iter().filter(|&&d| d <= 1.0).count();
    Ok(format!(
        "{label}: ΔE2000 per record median {:.2}, p90 {:.2}, max {:.2}, ≤ 1.0 in {}/{}; mean colour per group/site median {:.2}, max {:.2}, ≤ 1.0 in {}/{}",
        quantile(&de, 0.5),
        quantile(&de, 0.9),
        quantile(&de, 1.0),
        within(&de),
        de.len(),
        quantile(&gde, 0.5),
        quantile(&gde, 1.0),
        within(&gde),
        gde.len()
    ))
}

/// CSV of the mean colours per group/site: measured, seed fit, chosen fit, and the two ΔE2000.
pub fn colours_csv(seed: &[RecordFit], chosen: &[RecordFit]) -> anyhow::Result<String> {
    let a = group_colours(seed, &record_colours(seed)?);
    let b = group_colours(chosen, &record_colours(chosen)?);
    let mut csv = String::from(
        "group_site,n,measured_l,measured_a,measured_b,seed_l,seed_a,seed_b,seed_de2000,model_l,model_a,model_b,model_de2000\n",
    );
    for ((k, n, s), (_, _, c)) in a.iter().zip(&b) {
        let (m, x, y) = (s.measured, s.model, c.model);
        let _ = writeln!(
            csv,
            "{k},{n},{:.2},{:.2},{:.2},{:.2},{:.2},{:.2},{:.3},{:.2},{:.2},{:.2},{:.3}",
            m.l,
            m.a,
            m.b,
            x.l,
            x.a,
            x.b,
            s.delta_e(),
            y.l,
            y.a,
            y.b,
            c.delta_e()
        );
    }
    Ok(csv)
}

/// Which free parameters sit on a bound, as "name=bound" words (empty: none).
#[must_use]
pub fn bounds_text(f: &RecordFit) -> String {
    let words: Vec<String> = f
        .fit
        .at_bounds()
        .iter()
        .map(|(p, b)| format!("{p}={b}"))
        .collect();
    words.join(" ")
}

/// One summary line: for each parameter that was ever free, the share of fits where it sat on a
/// bound (and which bound).
#[must_use]
pub fn bounds_summary(label: &str, fits: &[RecordFit]) -> String {
    let mut all = Parameter::SEED.to_vec();
    all.push(Parameter::Oiliness);
    all.extend(Parameter::CANDIDATES);
    let mut parts = Vec::new();
    for p in all {
        let free = fits
            .iter()
            .filter(|f| f.fit.parameters.contains(&p))
            .count();
        if free == 0 {
            continue;
        }
        let [lo, hi] = p.range();
        let count = |bound: f64| {
            fits.iter()
                .filter(|f| f.fit.at_bounds().contains(&(p, bound)))
                .count()
        };
        let (at_lo, at_hi) = (count(lo), count(hi));
        if at_lo + at_hi > 0 {
            let pct = |c: usize| 100.0 * c as f64 / free as f64;
            parts.push(format!(
                "{p} {:.0} % at {lo} / {:.0} % at {hi} (of {free})",
                pct(at_lo),
                pct(at_hi)
            ));
        }
    }
    let any = fits
        .iter()
        .filter(|f| !f.fit.at_bounds().is_empty())
        .count();
    format!(
        "{label}: {any}/{} fits have a parameter on a bound; {}",
        fits.len(),
        parts.join(", ")
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A perfect white reflector is the D65 white point (L* 100, a* = b* = 0) to rounding; a
    /// grey of 18% has L* = 116 · 0.18^(1/3) − 16 = 49.5; uneven wavelengths are refused.
    #[test]
    fn lab_of_white_grey_and_uneven_grids() {
        let nm: Vec<f64> = (0..31).map(|i| 400.0 + 10.0 * f64::from(i)).collect();
        let white = lab_of(&nm, &[1.0; 31]).unwrap();
        assert!((white.l - 100.0).abs() < 1e-9 && white.a.abs() < 1e-9 && white.b.abs() < 1e-9);
        let grey = lab_of(&nm, &[0.18; 31]).unwrap();
        let want = 116.0 * 0.18_f64.cbrt() - 16.0;
        assert!((grey.l - want).abs() < 1e-9, "{grey:?}");
        let mut uneven = nm.clone();
        uneven[3] += 1.0;
        assert!(lab_of(&uneven, &[0.5; 31]).is_err());
    }
}
