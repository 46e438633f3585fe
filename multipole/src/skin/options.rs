//! The knobs of a skin profile: the diffusion knobs of both methods, and the exact method's shape,
//! shape spacing, phase function and surface.

use crate::diffusion::spatial::DiffusionOptions;
use crate::error::{MultipoleError, check_option};
use crate::layered::Surface;
use crate::skin::ExactShape;

/// Knobs of a skin profile computation ([`crate::skin::profile`], [`crate::SpectralProfiles`]);
/// every approximation here has one.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ProfileOptions {
    /// The diffusion knobs: the multipole's poles, the radial table and the inverse transform. The
    /// exact method inverts the same transforms with scaled layers, so they apply to both methods.
    pub diffusion: DiffusionOptions,
    /// Shape of `Method::Exact` profiles (default [`ExactShape::Table`], the shape table).
    pub exact_shape: ExactShape,
    /// Wavelength spacing of run-time Monte Carlo shapes ([`ExactShape::MonteCarlo`]) in
    /// `SpectralProfiles`, nm (default 10; [0.01, 1000]):
    /// rows between two shape wavelengths mix their unit-energy shapes linearly in λ, each row
    /// scaled to its own exact total.
    pub shape_step_nm: f64,
    /// Henyey–Greenstein anisotropy g of both skin layers for `Method::Exact` (default
    /// [`crate::DEFAULT_G`] = 0.9; [0, 0.99], adding-doubling's range): σs = σs'/(1 − g), the
    /// totals and the exact shapes are computed at this g (diffusion sees only σs').
    pub phase_g: f64,
    /// The skin's surface for `Method::Exact`'s totals and Monte Carlo shapes (default
    /// [`Surface::Fresnel`], the model's boundary; the renderer's oily surface passes its lobe,
    /// docs/physics.md §10.1). Diffusion (`Method::Multipole`) keeps the paper's Fresnel boundary,
    /// and the shape table's white runs are traced under it.
    pub surface: Surface,
}

impl Default for ProfileOptions {
    fn default() -> Self {
        Self {
            diffusion: DiffusionOptions::default(),
            exact_shape: ExactShape::default(),
            shape_step_nm: 10.0,
            phase_g: crate::DEFAULT_G,
            surface: Surface::Fresnel,
        }
    }
}

impl ProfileOptions {
    /// The default knobs with the converged diffusion setting [`DiffusionOptions::reference`].
    #[must_use]
    pub fn reference() -> Self {
        Self {
            diffusion: DiffusionOptions::reference(),
            ..Self::default()
        }
    }

    /// The default knobs with the diffusion knobs `diffusion`.
    #[must_use]
    pub fn with_diffusion(diffusion: DiffusionOptions) -> Self {
        Self {
            diffusion,
            ..Self::default()
        }
    }

    /// Check every knob; the error names the knob and its range.
    pub fn validate(&self) -> Result<(), MultipoleError> {
        check_option("phase_g", self.phase_g, 0.0, 0.99, "[0, 0.99]")?;
        check_option(
            "shape_step_nm",
            self.shape_step_nm,
            0.01,
            1000.0,
            "[0.01, 1000] nm",
        )?;
        self.diffusion.validate()
    }
}
