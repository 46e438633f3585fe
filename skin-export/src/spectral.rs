//! The skin as the spectral formats write it: per wavelength, each layer's σa, σs (not reduced), g, n
//! and thickness, taken from the one layer description `multipole` builds from the skin's parameters
//! (σs = σs'/(1 − g), docs/physics.md §6, §11), with the exact totals `skin spectrum` prints.

use crate::error::ExportError;
use crate::volume::{semi_infinite_total, solve_decreasing};
use multipole::Method;
use multipole::{DEFAULT_G, Layer, LayeredMedium};
use skin_optics::{SkinParams, WavelengthGrid};

/// One homogeneous layer: σa, σs (mm⁻¹), HG g, index n, thickness (mm; `None` = semi-infinite).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LayerOptics {
    /// Absorption coefficient σa, mm⁻¹.
    pub sigma_a_per_mm: f64,
    /// Scattering coefficient σs, mm⁻¹.
    pub sigma_s_per_mm: f64,
    /// Henyey–Greenstein anisotropy g.
    pub g: f64,
    /// Refractive index n.
    pub n: f64,
    /// Thickness, mm; `None` for the semi-infinite dermis.
    pub thickness_mm: Option<f64>,
}

impl LayerOptics {
    fn from_layer(l: &Layer) -> Self {
        Self {
            sigma_a_per_mm: l.sigma_a(),
            sigma_s_per_mm: l.sigma_s(),
            g: l.g(),
            n: l.n(),
            thickness_mm: l.thickness_mm(),
        }
    }

    /// The layer with lengths × k: coefficients ÷ k, thickness × k.
    #[must_use]
    pub fn with_lengths_scaled(self, k: f64) -> Self {
        Self {
            sigma_a_per_mm: self.sigma_a_per_mm / k,
            sigma_s_per_mm: self.sigma_s_per_mm / k,
            thickness_mm: self.thickness_mm.map(|d| d * k),
            ..self
        }
    }

    /// Extinction σa + σs, mm⁻¹.
    #[must_use]
    pub fn sigma_t_per_mm(&self) -> f64 {
        self.sigma_a_per_mm + self.sigma_s_per_mm
    }

    /// Single-scattering albedo σs/σt.
    #[must_use]
    pub fn albedo(&self) -> f64 {
        self.sigma_s_per_mm / self.sigma_t_per_mm()
    }
}

/// One wavelength of the skin: its layers (top first) and exact totals.
#[derive(Debug, Clone, PartialEq)]
pub struct SpectralRow {
    /// Wavelength, nm.
    pub lambda_nm: f64,
    /// Layers, top first (epidermis, dermis).
    pub layers: Vec<LayerOptics>,
    /// Exact total reflectance per unit flux entering (adding-doubling, `Method::Exact`).
    pub total: f64,
    /// The observable (1 − F_r(0)) × total, per unit incident flux: `skin spectrum`'s column.
    pub diffuse_reflectance: f64,
}

/// The skin on a wavelength grid, in air.
#[derive(Debug, Clone, PartialEq)]
pub struct SpectralSkin {
    /// One row per grid wavelength.
    pub rows: Vec<SpectralRow>,
    /// Index of the medium above the skin (air, 1).
    pub n_above: f64,
}

impl SpectralSkin {
    /// Layers and exact totals of `skin` at every wavelength of `grid` (HG g = the skin default 0.9).
    pub fn new(skin: &SkinParams, grid: &WavelengthGrid) -> Result<Self, ExportError> {
        let rows = grid
            .iter()
            .map(|lambda| {
                let stack = LayeredMedium::skin(skin, lambda, DEFAULT_G)?;
                Ok(SpectralRow {
                    lambda_nm: lambda.nm(),
                    layers: Self::layers_of(&stack),
                    total: multipole::skin::total_reflectance(skin, lambda, Method::Exact)?,
                    diffuse_reflectance: multipole::skin::diffuse_reflectance(
                        skin,
                        lambda,
                        Method::Exact,
                    )?,
                })
            })
            .collect::<Result<Vec<_>, ExportError>>()?;
        Ok(Self { rows, n_above: 1.0 })
    }

    /// The layers of a layered medium, top first.
    #[must_use]
    pub fn layers_of(stack: &LayeredMedium) -> Vec<LayerOptics> {
        stack.layers().iter().map(LayerOptics::from_layer).collect()
    }

    /// The same skin with every length × k (totals unchanged: transport is scale-free).
    #[must_use]
    pub fn with_lengths_scaled(&self, k: f64) -> Self {
        let mut out = self.clone();
        for row in &mut out.rows {
            for l in &mut row.layers {
                *l = l.with_lengths_scaled(k);
            }
        }
        out
    }
}

/// The layers of `layers` as `multipole`'s layered medium (the last layer semi-infinite if it has no
/// thickness).
pub fn to_stack(
    layers: &[LayerOptics],
    n_above: f64,
    n_below: f64,
) -> Result<LayeredMedium, ExportError> {
    let layers = layers
        .iter()
        .map(|l| match l.thickness_mm {
            Some(d) => Layer::slab(l.sigma_a_per_mm, l.sigma_s_per_mm, l.g, l.n, d),
            None => Layer::semi_infinite(l.sigma_a_per_mm, l.sigma_s_per_mm, l.g, l.n),
        })
        .collect::<Result<Vec<_>, _>>()?;
    Ok(LayeredMedium::new(layers, n_above, n_below)?)
}

/// The single semi-infinite layer that returns the row's exact total: the dermis' scattering, g and
/// n, with σa (mm⁻¹) found by bisection on the adding-doubling total (for renderers whose subsurface
/// model has one layer).
pub fn single_layer_equivalent(row: &SpectralRow) -> Result<LayerOptics, ExportError> {
    let dermis = *row.layers.last().expect("a skin has layers");
    let total =
        |sigma_a: f64| semi_infinite_total(sigma_a, dermis.sigma_s_per_mm, dermis.g, dermis.n);
    let sigma_a = solve_decreasing(row.total, 1e-8, 1e4, total)?;
    Ok(LayerOptics {
        sigma_a_per_mm: sigma_a,
        thickness_mm: None,
        ..dermis
    })
}
