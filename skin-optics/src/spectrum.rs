//! Uniform wavelength grids and spectra tabulated on them (tabulation, not physics).

use crate::error::OpticsError;
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
    /// A grid from `from_nm` to `to_nm` inclusive (the last point is the largest one ≤ `to_nm`),
    /// with step `step_nm` > 0; both ends must be valid [`Wavelength`]s.
    pub fn new(from_nm: f64, to_nm: f64, step_nm: f64) -> Result<Self, OpticsError> {
        let from = Wavelength::new(from_nm).map_err(|e| rename(e, "--from wavelength (nm)"))?;
        let to = Wavelength::new(to_nm).map_err(|e| rename(e, "--to wavelength (nm)"))?;
        if !step_nm.is_finite() || step_nm <= 0.0 {
            return Err(OpticsError::OutOfRange {
                name: "wavelength step (nm)",
                value: step_nm,
                range: "(0, 750] nm",
            });
        }
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
