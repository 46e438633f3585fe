//! Uniform wavelength grids and spectra tabulated on them (tabulation, not physics).

use crate::error::{OpticsError, check_range};
use crate::units::Wavelength;

/// A uniform grid of wavelengths `start_nm + i · step_nm`, i = 0..count, all inside
/// [`Wavelength::MIN_NM`, `Wavelength::MAX_NM`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WavelengthGrid {
    start_nm: f64,
    step_nm: f64,
    count: usize,
}

impl WavelengthGrid {
    /// Smallest accepted grid step, nm (keeps a grid over the whole range below 75 001 points).
    pub const MIN_STEP_NM: f64 = 0.01;
    /// Largest accepted grid step, nm (the width of the supported range).
    pub const MAX_STEP_NM: f64 = 750.0;

    /// A grid from `from_nm` to `to_nm` inclusive (the last point is the largest one ≤ `to_nm`),
    /// with step `step_nm` in [0.01, 750] nm; both ends must be valid [`Wavelength`]s and
    /// `to_nm ≥ from_nm`.
    pub fn new(from_nm: f64, to_nm: f64, step_nm: f64) -> Result<Self, OpticsError> {
        let from = Wavelength::new(from_nm).map_err(|e| rename(e, "grid start (nm)"))?;
        let to = Wavelength::new(to_nm).map_err(|e| rename(e, "grid end (nm)"))?;
        check_range(
            "grid step (nm)",
            step_nm,
            Self::MIN_STEP_NM,
            Self::MAX_STEP_NM,
            "[0.01, 750] nm",
        )?;
        if to.nm() < from.nm() {
            return Err(OpticsError::Grid(format!(
                "end {to_nm} nm is below start {from_nm} nm"
            )));
        }
        // The 1e-9 guard keeps 400..=700 step 10 at 31 points despite rounding.
        let count = ((to.nm() - from.nm()) / step_nm + 1e-9).floor() as usize + 1;
        Ok(Self {
            start_nm: from.nm(),
            step_nm,
            count,
        })
    }

    /// The standard visible grid of the model: 400–700 nm every 10 nm (31 wavelengths).
    #[must_use]
    pub fn visible() -> Self {
        Self {
            start_nm: 400.0,
            step_nm: 10.0,
            count: 31,
        }
    }

    /// Number of wavelengths.
    #[must_use]
    pub fn len(&self) -> usize {
        self.count
    }

    /// True when the grid has no wavelengths (never, for a constructed grid).
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.count == 0
    }

    /// First wavelength, nm.
    #[must_use]
    pub fn start_nm(&self) -> f64 {
        self.start_nm
    }

    /// Spacing, nm.
    #[must_use]
    pub fn step_nm(&self) -> f64 {
        self.step_nm
    }

    /// Wavelength `i`, nm.
    #[must_use]
    pub fn nm(&self, i: usize) -> f64 {
        self.start_nm + self.step_nm * i as f64
    }

    /// Wavelength `i` as a validated [`Wavelength`].
    #[must_use]
    pub fn wavelength(&self, i: usize) -> Wavelength {
        // Every grid point lies between two validated ends.
        Wavelength::new(self.nm(i).min(Wavelength::MAX_NM)).expect("grid point inside range")
    }

    /// Iterator over the wavelengths.
    pub fn iter(&self) -> impl Iterator<Item = Wavelength> + '_ {
        (0..self.count).map(|i| self.wavelength(i))
    }
}

fn rename(e: OpticsError, name: &'static str) -> OpticsError {
    match e {
        OpticsError::NonFinite { value, range, .. } => {
            OpticsError::NonFinite { name, value, range }
        }
        OpticsError::OutOfRange { value, range, .. } => {
            OpticsError::OutOfRange { name, value, range }
        }
        other => other,
    }
}

/// A spectrum tabulated on a [`WavelengthGrid`] (e.g. a reflectance, dimensionless).
#[derive(Debug, Clone, PartialEq)]
pub struct GridSpectrum {
    grid: WavelengthGrid,
    values: Vec<f64>,
}

impl GridSpectrum {
    /// Tabulate `f(λ)` on `grid`.
    pub fn from_fn(grid: WavelengthGrid, f: impl Fn(Wavelength) -> f64) -> Self {
        let values = grid.iter().map(f).collect();
        Self { grid, values }
    }

    /// A spectrum from values, one per grid point.
    pub fn new(grid: WavelengthGrid, values: Vec<f64>) -> Result<Self, OpticsError> {
        if values.len() != grid.len() {
            return Err(OpticsError::Grid(format!(
                "{} values for a grid of {} wavelengths",
                values.len(),
                grid.len()
            )));
        }
        Ok(Self { grid, values })
    }

    /// The grid.
    #[must_use]
    pub fn grid(&self) -> &WavelengthGrid {
        &self.grid
    }

    /// The values, one per grid point.
    #[must_use]
    pub fn values(&self) -> &[f64] {
        &self.values
    }

    /// Linear interpolation at `nm`, held constant beyond the grid's ends.
    #[must_use]
    pub fn at_nm(&self, nm: f64) -> f64 {
        let n = self.values.len();
        if n == 1 {
            return self.values[0];
        }
        let x = ((nm - self.grid.start_nm) / self.grid.step_nm).clamp(0.0, (n - 1) as f64);
        let i = (x.floor() as usize).min(n - 2);
        let t = x - i as f64;
        self.values[i] * (1.0 - t) + self.values[i + 1] * t
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn visible_grid_is_400_to_700_by_10() {
        let g = WavelengthGrid::new(400.0, 700.0, 10.0).unwrap();
        assert_eq!(g, WavelengthGrid::visible());
        assert_eq!(g.len(), 31);
        assert_eq!((g.nm(0), g.nm(30)), (400.0, 700.0));
        let nms: Vec<f64> = g.iter().map(Wavelength::nm).collect();
        assert_eq!(nms[15], 550.0);
    }

    #[test]
    fn grid_ends_at_largest_point_not_above_to() {
        let g = WavelengthGrid::new(400.0, 700.0, 7.0).unwrap();
        assert_eq!(g.len(), 43);
        assert_eq!(g.nm(42), 694.0);
        let one = WavelengthGrid::new(550.0, 550.0, 5.0).unwrap();
        assert_eq!(one.len(), 1);
        let full = WavelengthGrid::new(250.0, 1000.0, 750.0).unwrap();
        assert_eq!((full.len(), full.nm(1)), (2, 1000.0));
        // 0.1 nm steps: rounding must not lose the end point.
        let fine = WavelengthGrid::new(400.0, 700.0, 0.1).unwrap();
        assert_eq!(fine.len(), 3001);
        assert!(fine.wavelength(3000).nm() <= 700.0 + 1e-9);
    }

    #[test]
    fn grid_errors_name_the_bad_parameter() {
        let kind = |r: Result<WavelengthGrid, OpticsError>| match r.unwrap_err() {
            OpticsError::OutOfRange { name, .. } => ("OutOfRange", name),
            OpticsError::NonFinite { name, .. } => ("NonFinite", name),
            OpticsError::Grid(_) => ("Grid", ""),
            OpticsError::GridMismatch => ("GridMismatch", ""),
        };
        assert_eq!(
            kind(WavelengthGrid::new(100.0, 700.0, 10.0)),
            ("OutOfRange", "grid start (nm)")
        );
        assert_eq!(
            kind(WavelengthGrid::new(f64::NAN, 700.0, 10.0)),
            ("NonFinite", "grid start (nm)")
        );
        assert_eq!(
            kind(WavelengthGrid::new(400.0, 1200.0, 10.0)),
            ("OutOfRange", "grid end (nm)")
        );
        assert_eq!(
            kind(WavelengthGrid::new(400.0, 700.0, 0.0)),
            ("OutOfRange", "grid step (nm)")
        );
        assert_eq!(
            kind(WavelengthGrid::new(400.0, 700.0, -10.0)),
            ("OutOfRange", "grid step (nm)")
        );
        assert_eq!(
            kind(WavelengthGrid::new(400.0, 700.0, 1e-6)),
            ("OutOfRange", "grid step (nm)")
        );
        assert_eq!(
            kind(WavelengthGrid::new(400.0, 700.0, 751.0)),
            ("OutOfRange", "grid step (nm)")
        );
        assert_eq!(
            kind(WavelengthGrid::new(400.0, 700.0, f64::NAN)),
            ("NonFinite", "grid step (nm)")
        );
        assert_eq!(kind(WavelengthGrid::new(700.0, 400.0, 10.0)), ("Grid", ""));
    }

    #[test]
    fn spectrum_length_must_match_grid() {
        let g = WavelengthGrid::visible();
        assert!(matches!(
            GridSpectrum::new(g, vec![0.5; 30]),
            Err(OpticsError::Grid(_))
        ));
        assert!(GridSpectrum::new(g, vec![0.5; 31]).is_ok());
    }

    #[test]
    fn spectrum_interpolates_and_holds_ends() {
        let g = WavelengthGrid::new(400.0, 420.0, 10.0).unwrap();
        let s = GridSpectrum::from_fn(g, |l| l.nm() / 100.0);
        assert_eq!(s.values(), &[4.0, 4.1, 4.2]);
        assert!((s.at_nm(405.0) - 4.05).abs() < 1e-12);
        assert_eq!(s.at_nm(300.0), 4.0);
        assert_eq!(s.at_nm(900.0), 4.2);
        assert_eq!(s.grid(), &g);
        let single =
            GridSpectrum::new(WavelengthGrid::new(500.0, 500.0, 1.0).unwrap(), vec![0.3]).unwrap();
        assert_eq!(single.at_nm(700.0), 0.3);
    }
}
