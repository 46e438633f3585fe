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

#[cfg(test)]
mod tests {
    use super::*;

    /// The embedded files have the shape the code assumes (uniform grid, expected columns).
    #[test]
    fn embedded_tables_have_the_expected_shape() {
        let shapes = [
            (
                include_str!("../data/hemoglobin_molar_extinction.csv"),
                250.0,
                2.0,
                376,
                2,
            ),
            (
                include_str!("../data/cie1931_2deg_cmf.csv"),
                360.0,
                1.0,
                471,
                3,
            ),
            (include_str!("../data/cie_d65.csv"), 300.0, 1.0, 531, 1),
            (
                include_str!("../data/bilirubin_molar_extinction.csv"),
                250.0,
                2.0,
                226,
                1,
            ),
        ];
        for (text, start, step, rows, cols) in shapes {
            let t = UniformTable::parse(text);
            assert_eq!(
                (t.start_nm, t.step_nm, t.columns.len()),
                (start, step, cols)
            );
            for c in &t.columns {
                assert_eq!(c.len(), rows);
            }
            // Uniform: every row's wavelength is start + i·step.
            let nms: Vec<f64> = text
                .lines()
                .filter(|l| !l.starts_with('#') && !l.trim().is_empty())
                .skip(1)
                .map(|l| l.split(',').next().unwrap().parse().unwrap())
                .collect();
            for (i, nm) in nms.iter().enumerate() {
                assert_eq!(*nm, start + step * i as f64);
            }
        }
    }

    #[test]
    fn lerp_is_linear_and_zero_outside() {
        let t = UniformTable::parse("# c\nx,a\n10,1\n20,3\n30,7\n");
        assert_eq!(t.lerp(0, 10.0), 1.0);
        assert_eq!(t.lerp(0, 15.0), 2.0);
        assert_eq!(t.lerp(0, 25.0), 5.0);
        assert_eq!(t.lerp(0, 30.0), 7.0);
        assert_eq!(t.lerp(0, 9.9), 0.0);
        assert_eq!(t.lerp(0, 30.1), 0.0);
    }
}
