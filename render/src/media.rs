//! A skin material's one spectral description: both layers' σa and σs on the 5-nm grid of
//! [`SpectrumTable`] at the material's own Henyey–Greenstein g, from
//! `multipole::LayeredMedium::skin` (the one σs' → σs conversion, docs/physics.md §2), computed
//! once when the material is built. The volumetric walk, the thin-part walk and the fidelity's
//! transport scale all read these numbers; none rebuilds them.

use crate::spectrum::{LAMBDA_MAX_NM, LAMBDA_MIN_NM, SpectrumTable};
use multipole::{LayeredMedium, MultipoleError, Surface};
use skin_optics::{SkinParams, Wavelength};

/// One layer's coefficients over the visible range, mm⁻¹.
#[derive(Debug, Clone)]
pub struct LayerTables {
    /// Absorption σa(λ), mm⁻¹.
    pub sigma_a: SpectrumTable,
    /// Scattering σs(λ) = σs'(λ) / (1 − g), mm⁻¹.
    pub sigma_s: SpectrumTable,
}

impl LayerTables {
    /// The same σa and σs (mm⁻¹) at every wavelength.
    #[must_use]
    pub fn constant(sigma_a_per_mm: f32, sigma_s_per_mm: f32) -> Self {
        Self {
            sigma_a: SpectrumTable::constant(sigma_a_per_mm),
            sigma_s: SpectrumTable::constant(sigma_s_per_mm),
        }
    }
}

/// A layer that could not be built at a wavelength.
#[derive(Debug, Clone, thiserror::Error)]
#[error("skin layers at {nm} nm: {source}")]
pub struct MediaError {
    /// The wavelength, nm.
    pub nm: f64,
    /// What the model reported.
    pub source: MultipoleError,
}

/// Both layers of one skin material at its anisotropy, on the 5-nm grid over 380–780 nm.
#[derive(Debug, Clone)]
pub struct SkinMedia {
    /// The epidermis' coefficients.
    pub epidermis: LayerTables,
    /// The dermis' coefficients.
    pub dermis: LayerTables,
    /// Henyey–Greenstein g of both layers.
    pub phase_g: f64,
    /// The dermis' largest transport mean free path 1/(σa + σs') every 10 nm over 380–780 nm, mm.
    pub largest_transport_mfp_mm: f64,
    /// What the skin's surface reflects from either side: the boundary of the totals
    /// (docs/physics.md §10.1; [`Surface::Fresnel`] unless [`Self::with_surface`] says otherwise).
    pub surface: Surface,
    /// The layered medium at every wavelength of the 5-nm grid, in f64 (what the totals take).
    layered: Vec<LayeredMedium>,
}

impl SkinMedia {
    /// The layers of `params` at anisotropy `g` in [0, 0.99]; an error names its wavelength.
    pub fn new(params: &SkinParams, g: f64) -> Result<Self, MediaError> {
        let step = f64::from(SpectrumTable::STEP_NM);
        let (from, to) = (f64::from(LAMBDA_MIN_NM), f64::from(LAMBDA_MAX_NM));
        let n = ((to - from) / step) as usize + 1;
        let mut rows = Vec::with_capacity(n);
        let mut layered = Vec::with_capacity(n);
        let mut largest_transport_mfp_mm = 0.0f64;
        for i in 0..n {
            let nm = from + step * i as f64;
            let err = |source| MediaError { nm, source };
            let lambda = Wavelength::new(nm).map_err(|e| err(MultipoleError::from(e)))?;
            let medium = LayeredMedium::skin(params, lambda, g).map_err(err)?;
            let layers = medium.layers();
            let (e, d) = (layers[0], layers[layers.len() - 1]);
            rows.push([e.sigma_a(), e.sigma_s(), d.sigma_a(), d.sigma_s()]);
            if (nm - from) % 10.0 == 0.0 {
                largest_transport_mfp_mm =
                    largest_transport_mfp_mm.max(1.0 / (d.sigma_a() + d.sigma_s_prime()));
            }
            layered.push(medium);
        }
        let table = |k: usize| {
            SpectrumTable::from_fn(|nm| rows[(((nm - from) / step).round() as usize).min(n - 1)][k])
        };
        Ok(Self {
            epidermis: LayerTables {
                sigma_a: table(0),
                sigma_s: table(1),
            },
            dermis: LayerTables {
                sigma_a: table(2),
                sigma_s: table(3),
            },
            phase_g: g,
            largest_transport_mfp_mm,
            surface: Surface::Fresnel,
            layered,
        })
    }

    /// The same layers under `surface`: what every total, gain and slab table built from them
    /// sees at the skin's faces.
    #[must_use]
    pub fn with_surface(mut self, surface: Surface) -> Self {
        self.layered = self
            .layered
            .into_iter()
            .map(|m| m.with_surface(surface))
            .collect();
        self.surface = surface;
        self
    }

    /// The layered medium every 10 nm from 380 to 780 nm, with its wavelength in nm.
    pub fn every_10nm(&self) -> impl Iterator<Item = (f64, &LayeredMedium)> {
        let step = f64::from(SpectrumTable::STEP_NM);
        self.layered
            .iter()
            .enumerate()
            .map(move |(i, m)| (f64::from(LAMBDA_MIN_NM) + step * i as f64, m))
            .filter(|(nm, _)| (nm - f64::from(LAMBDA_MIN_NM)) % 10.0 == 0.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use skin_optics::Preset;

    /// The tables hold `LayeredMedium::skin`'s coefficients at the grid's wavelengths (f32
    /// rounding, 1e-6 relative) and σs = σs'/(1 − g) at the material's g; a g outside
    /// adding-doubling's range names its wavelength.
    #[test]
    fn the_tables_are_the_layered_medium_at_the_materials_g() {
        let params = SkinParams::preset(Preset::Medium);
        let media = SkinMedia::new(&params, 0.8).unwrap();
        for nm in [380.0, 455.0, 550.0, 780.0] {
            let m = LayeredMedium::skin(&params, Wavelength::new(nm).unwrap(), 0.8).unwrap();
            let (e, d) = (m.layers()[0], m.layers()[1]);
            let rel = |a: f32, b: f64| (f64::from(a) / b - 1.0).abs();
            assert!(rel(media.epidermis.sigma_a.at_nm(nm as f32), e.sigma_a()) < 1e-6);
            assert!(rel(media.epidermis.sigma_s.at_nm(nm as f32), e.sigma_s()) < 1e-6);
            assert!(rel(media.dermis.sigma_a.at_nm(nm as f32), d.sigma_a()) < 1e-6);
            assert!(
                rel(
                    media.dermis.sigma_s.at_nm(nm as f32),
                    d.sigma_s_prime() / 0.2
                ) < 1e-6
            );
        }
        assert_eq!(media.phase_g, 0.8);
        let tens: Vec<f64> = media.every_10nm().map(|(nm, _)| nm).collect();
        assert_eq!((tens.len(), tens[0], tens[40]), (41, 380.0, 780.0));
        let mfp = media.largest_transport_mfp_mm;
        assert!(mfp > 0.1 && mfp < 10.0, "{mfp}");
        let e = SkinMedia::new(&params, 1.5).unwrap_err();
        assert_eq!(e.nm, 380.0);
    }
}
