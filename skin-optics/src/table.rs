//! Parsing and linear interpolation of the embedded CSV tables (data, not physics).

/// A table sampled on a uniform wavelength grid: `columns[c][i]` is column `c` at `start_nm + i * step_nm`.
#[derive(Debug, Clone)]
pub(crate) struct UniformTable {
    pub start_nm: f64,
    pub step_nm: f64,
    pub columns: Vec<Vec<f64>>,
}

impl UniformTable {
    /// Parse an embedded CSV whose comment lines start with `#`, then a header, then rows of numbers
    /// on a uniform wavelength grid. Only called on files compiled into the crate, whose shape the
    /// unit tests check, so a malformed file is a build-time defect, reported by panic.
    pub fn parse(text: &str) -> Self {
        let mut rows: Vec<Vec<f64>> = Vec::new();
        let mut header_seen = false;
        for line in text.lines() {
            let line = line.trim();
            if line.is_empty() || line.starts_with('#') {
                continue;
            }
            if !header_seen {
                header_seen = true;
                continue;
            }
            rows.push(
                line.split(',')
                    .map(|f| f.trim().parse::<f64>().expect("embedded table: number"))
                    .collect(),
            );
        }
        let start_nm = rows[0][0];
        let step_nm = rows[1][0] - rows[0][0];
        let ncol = rows[0].len() - 1;
        let columns = (0..ncol)
            .map(|c| rows.iter().map(|r| r[c + 1]).collect())
            .collect();
        Self {
            start_nm,
            step_nm,
            columns,
        }
    }

    /// Linear interpolation of column `c` at `nm`; zero outside the table (callers that must not
    /// extrapolate validate the wavelength first).
    pub fn lerp(&self, c: usize, nm: f64) -> f64 {
        let col = &self.columns[c];
        let x = (nm - self.start_nm) / self.step_nm;
        if !(0.0..=(col.len() - 1) as f64).contains(&x) {
            return 0.0;
        }
        let i = (x.floor() as usize).min(col.len() - 2);
        let t = x - i as f64;
        col[i] * (1.0 - t) + col[i + 1] * t
    }
}
