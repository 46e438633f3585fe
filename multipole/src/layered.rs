//! The one description of a layered medium, shared by every transport method: each layer's σa,
//! σs (and σs'), Henyey–Greenstein g, index n and thickness, with the ambient indices above and
//! below. Diffusion ([`crate::diffusion::stack::Stack::from_medium`]), adding-doubling
//! ([`crate::exact::adding_doubling::solve`]) and the Monte Carlo
//! ([`crate::exact::montecarlo::run`]) all take a [`LayeredMedium`]; [`LayeredMedium::skin`] builds the two-layer skin from its parameters
//! (docs/physics.md §1, §6). The default anisotropy, the σs'→σs conversion and the valid ranges
//! live here and nowhere else.
//!
//! `Layer::checked` is the single constructor every public one funnels into, where the ranges are
//! checked.

use crate::error::{MultipoleError, check_range};
use skin_optics::{SkinParams, Wavelength};

/// Largest accepted absorption or scattering coefficient, mm⁻¹ (beyond it a history is one step long).
pub const MAX_COEFFICIENT_PER_MM: f64 = 1.0e4;
/// Largest accepted finite layer thickness, mm.
pub const MAX_THICKNESS_MM: f64 = 1.0e3;

/// Default Henyey–Greenstein anisotropy of skin layers, typical of tissue ([Prahl95]; the seed
/// gives only σs'): σs = σs' / (1 − g).
pub const DEFAULT_G: f64 = 0.9;

/// One homogeneous layer: σa, σs (mm⁻¹), HG anisotropy g, index n, thickness (mm, or semi-infinite).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Layer {
    sigma_a: f64,
    sigma_s: f64,
    /// σs(1 − g) as given or derived: kept so that a layer built from σs' returns it unrounded.
    sigma_s_prime: f64,
    g: f64,
    n: f64,
    thickness_mm: Option<f64>,
}

impl Layer {
    fn checked(
        sigma_a: f64,
        sigma_s: f64,
        sigma_s_prime: f64,
        g: f64,
        n: f64,
        thickness_mm: Option<f64>,
    ) -> Result<Self, MultipoleError> {
        if thickness_mm.is_none() && (sigma_a.is_nan() || sigma_a <= 0.0) {
            return Err(MultipoleError::OutOfRange {
                name: "absorption σa of a semi-infinite layer (mm⁻¹)",
                value: sigma_a,
                range: "(0, 1e4] mm⁻¹",
            });
        }
        let range = "[0, 1e4] mm⁻¹";
        check_range(
            "absorption σa (mm⁻¹)",
            sigma_a,
            0.0,
            MAX_COEFFICIENT_PER_MM,
            range,
        )?;
        check_range(
            "scattering σs (mm⁻¹)",
            sigma_s,
            0.0,
            MAX_COEFFICIENT_PER_MM,
            range,
        )?;
        check_range("anisotropy g", g, -0.999, 0.999, "[-0.999, 0.999]")?;
        check_range("layer index n", n, 1.0, 3.0, "[1, 3]")?;
        if let Some(d) = thickness_mm
            && (d.is_nan() || d <= 0.0 || d > MAX_THICKNESS_MM)
        {
            return Err(MultipoleError::OutOfRange {
                name: "layer thickness (mm)",
                value: d,
                range: "(0, 1000] mm",
            });
        }
        Ok(Self {
            sigma_a,
            sigma_s,
            sigma_s_prime,
            g,
            n,
            thickness_mm,
        })
    }

    /// A slab of finite thickness: σa, σs in [0, 1e4] mm⁻¹, g in [−0.999, 0.999], n in [1, 3],
    /// thickness in (0, 1000] mm. σa = σs = 0 is a clear (glass) layer.
    pub fn slab(
        sigma_a: f64,
        sigma_s: f64,
        g: f64,
        n: f64,
        thickness_mm: f64,
    ) -> Result<Self, MultipoleError> {
        Self::checked(
            sigma_a,
            sigma_s,
            sigma_s * (1.0 - g),
            g,
            n,
            Some(thickness_mm),
        )
    }

    /// A semi-infinite layer (only as the last of a stack). It needs σa > 0: without absorption a
    /// history in a half-space has unbounded expected length.
    pub fn semi_infinite(
        sigma_a: f64,
        sigma_s: f64,
        g: f64,
        n: f64,
    ) -> Result<Self, MultipoleError> {
        Self::checked(sigma_a, sigma_s, sigma_s * (1.0 - g), g, n, None)
    }

    /// A layer given by its reduced scattering σs' (mm⁻¹): σs = σs' / (1 − g).
    /// `thickness_mm = None` makes it semi-infinite.
    pub fn from_reduced(
        sigma_a: f64,
        sigma_s_prime: f64,
        g: f64,
        n: f64,
        thickness_mm: Option<f64>,
    ) -> Result<Self, MultipoleError> {
        check_range("anisotropy g", g, -0.999, 0.999, "[-0.999, 0.999]")?;
        let sigma_s = sigma_s_prime / (1.0 - g);
        Self::checked(sigma_a, sigma_s, sigma_s_prime, g, n, thickness_mm)
    }

    /// Absorption coefficient σa, mm⁻¹.
    #[must_use]
    pub fn sigma_a(&self) -> f64 {
        self.sigma_a
    }
    /// Scattering coefficient σs, mm⁻¹.
    #[must_use]
    pub fn sigma_s(&self) -> f64 {
        self.sigma_s
    }
    /// Reduced scattering coefficient σs' = σs (1 − g), mm⁻¹ (what diffusion uses).
    #[must_use]
    pub fn sigma_s_prime(&self) -> f64 {
        self.sigma_s_prime
    }
    /// Henyey–Greenstein anisotropy g (mean cosine of the scattering angle).
    #[must_use]
    pub fn g(&self) -> f64 {
        self.g
    }
    /// Index of refraction n.
    #[must_use]
    pub fn n(&self) -> f64 {
        self.n
    }
    /// Thickness in mm; `None` for a semi-infinite layer.
    #[must_use]
    pub fn thickness_mm(&self) -> Option<f64> {
        self.thickness_mm
    }
    /// Single-scattering albedo σs / (σa + σs) (0 for a clear layer).
    #[must_use]
    pub fn albedo(&self) -> f64 {
        let t = self.sigma_a + self.sigma_s;
        if t > 0.0 { self.sigma_s / t } else { 0.0 }
    }
    /// Optical thickness τ = (σa + σs) d, dimensionless (0 for a clear layer; infinite for a
    /// semi-infinite one that attenuates).
    #[must_use]
    pub fn optical_thickness(&self) -> f64 {
        let st = self.sigma_a + self.sigma_s;
        if st == 0.0 {
            0.0
        } else {
            st * self.thickness_mm.unwrap_or(f64::INFINITY)
        }
    }
}

/// What the stack's faces to the ambient media reflect, from either side (docs/physics.md §10.1).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum Surface {
    /// A smooth dielectric: exact unpolarised Fresnel reflectance (the model's own boundary, [DJ06];
    /// the renderer's `surface = "smooth"`).
    #[default]
    Fresnel,
    /// The oily Torrance–Sparrow lobe of [DJ06] (docs/physics.md §7) as the boundary: a direction
    /// that refracts through the face is reflected with the lobe's directional albedo ρ_dr at its
    /// outside angle and transmitted along Snell's direction otherwise; beyond the critical angle it
    /// is totally reflected. What the renderer's oily surface does to light in both directions.
    Lobe {
        /// Beckmann RMS slope m, (0, 1].
        roughness_m: f64,
        /// Oiliness ρ_s, [0, 1].
        oiliness_rho_s: f64,
    },
}

impl Surface {
    /// The oily lobe of Beckmann RMS slope `roughness_m` in (0, 1] and oiliness `oiliness_rho_s`
    /// in [0, 1].
    pub fn lobe(roughness_m: f64, oiliness_rho_s: f64) -> Result<Self, MultipoleError> {
        if roughness_m.is_nan() || roughness_m <= 0.0 || roughness_m > 1.0 {
            return Err(MultipoleError::OutOfRange {
                name: "surface roughness m",
                value: roughness_m,
                range: "(0, 1]",
            });
        }
        check_range("oiliness ρ_s", oiliness_rho_s, 0.0, 1.0, "[0, 1]")?;
        Ok(Self::Lobe {
            roughness_m,
            oiliness_rho_s,
        })
    }

    /// The face's reflector for a stack of index `n_slab` under an ambient medium of index
    /// `n_outside`, built once per solve or run.
    pub(crate) fn reflector(&self, n_slab: f64, n_outside: f64) -> FaceReflector {
        let lobe = match *self {
            Surface::Fresnel => None,
            Surface::Lobe {
                roughness_m,
                oiliness_rho_s,
            } => brdf::TorranceSparrow::new(
                roughness_m as f32,
                oiliness_rho_s as f32,
                (n_slab / n_outside) as f32,
            )
            .ok(),
        };
        FaceReflector {
            ratio: n_outside / n_slab,
            lobe,
        }
    }
}

/// One face's reflectance as a function of the direction's cosine inside the stack.
#[derive(Debug, Clone)]
pub(crate) struct FaceReflector {
    /// n_outside / n_slab.
    ratio: f64,
    lobe: Option<brdf::TorranceSparrow>,
}

impl FaceReflector {
    /// The probability that light meeting the face at cosine `mu_inside` (or arriving from outside
    /// along the direction that refracts into it) is reflected: Fresnel, or the lobe's ρ_dr at the
    /// outside cosine; 1 beyond the critical angle either way.
    pub(crate) fn reflectance(&self, mu_inside: f64) -> f64 {
        let fresnel = brdf::fresnel::dielectric_reflectance(mu_inside, self.ratio);
        match &self.lobe {
            Some(lobe) if fresnel < 1.0 => {
                let sin2_out = (1.0 - mu_inside * mu_inside) / (self.ratio * self.ratio);
                let mu_out = (1.0 - sin2_out).max(0.0).sqrt();
                f64::from(lobe.directional_albedo(mu_out as f32)).clamp(0.0, 1.0)
            }
            _ => fresnel,
        }
    }
}

/// Layers from the top (lit) face down, with the ambient indices above and below.
#[derive(Debug, Clone, PartialEq)]
pub struct LayeredMedium {
    layers: Vec<Layer>,
    n_above: f64,
    n_below: f64,
    surface: Surface,
}

impl LayeredMedium {
    /// A stack of at least one layer; only the last may be semi-infinite (then `n_below` is unused).
    /// Ambient indices in [1, 3].
    pub fn new(layers: Vec<Layer>, n_above: f64, n_below: f64) -> Result<Self, MultipoleError> {
        check_range("ambient index above", n_above, 1.0, 3.0, "[1, 3]")?;
        check_range("ambient index below", n_below, 1.0, 3.0, "[1, 3]")?;
        if layers.is_empty() {
            return Err(MultipoleError::Layers("no layers".into()));
        }
        if let Some(i) = layers[..layers.len() - 1]
            .iter()
            .position(|l| l.thickness_mm.is_none())
        {
            return Err(MultipoleError::Layers(format!(
                "layer {i} is semi-infinite but not the last of {}",
                layers.len()
            )));
        }
        Ok(Self {
            layers,
            n_above,
            n_below,
            surface: Surface::Fresnel,
        })
    }

    /// The same stack with `surface` on its faces to the ambient media (adding-doubling and the
    /// Monte Carlo honour it; diffusion keeps the paper's Fresnel boundary, docs/physics.md §10.1).
    #[must_use]
    pub fn with_surface(mut self, surface: Surface) -> Self {
        self.surface = surface;
        self
    }

    /// What the faces to the ambient media reflect.
    #[must_use]
    pub fn surface(&self) -> Surface {
        self.surface
    }

    /// [DJ06] skin at one wavelength: an epidermis of the skin's thickness over a semi-infinite
    /// dermis, both of index `skin.eta()`, in air (n = 1). σa and σs' come from
    /// `SkinParams::coefficients` (eqs 1–6); σs = σs' / (1 − g) with HG anisotropy `g`
    /// ([`DEFAULT_G`] = 0.9 is the usual choice). The dermis is semi-infinite as in the model
    /// ([DJ05] stacks the epidermis slab on a dipole half-space).
    pub fn skin(skin: &SkinParams, lambda: Wavelength, g: f64) -> Result<Self, MultipoleError> {
        let c = skin.coefficients(lambda);
        let n = skin.eta();
        let epidermis = Layer::from_reduced(
            c.epidermis.sigma_a,
            c.epidermis.sigma_s_prime,
            g,
            n,
            Some(skin.epidermis_thickness_mm()),
        )?;
        let dermis = Layer::from_reduced(c.dermis.sigma_a, c.dermis.sigma_s_prime, g, n, None)?;
        Self::new(vec![epidermis, dermis], 1.0, 1.0)
    }

    /// The layers, top first.
    #[must_use]
    pub fn layers(&self) -> &[Layer] {
        &self.layers
    }
    /// Ambient index of refraction above the stack (the lit side).
    #[must_use]
    pub fn n_above(&self) -> f64 {
        self.n_above
    }
    /// Ambient index of refraction below the stack (unused when the last layer is semi-infinite).
    #[must_use]
    pub fn n_below(&self) -> f64 {
        self.n_below
    }
    /// Whether the last layer is semi-infinite (nothing can be transmitted).
    #[must_use]
    pub fn is_semi_infinite(&self) -> bool {
        self.layers.last().is_some_and(|l| l.thickness_mm.is_none())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rejects_bad_layers_naming_the_parameter() {
        let e = Layer::slab(-1.0, 1.0, 0.9, 1.4, 1.0).unwrap_err();
        assert!(e.to_string().contains("σa"), "{e}");
        assert!(Layer::slab(0.1, 1.0, 1.0, 1.4, 1.0).is_err());
        assert!(Layer::slab(0.1, 1.0, 0.9, 1.4, 0.0).is_err());
        assert!(Layer::semi_infinite(0.0, 1.0, 0.9, 1.4).is_err());
        let semi = Layer::semi_infinite(0.1, 1.0, 0.9, 1.4).unwrap();
        let slab = Layer::slab(0.1, 1.0, 0.9, 1.4, 1.0).unwrap();
        assert!(LayeredMedium::new(vec![semi, slab], 1.0, 1.0).is_err());
        assert!(LayeredMedium::new(vec![], 1.0, 1.0).is_err());
        assert!(LayeredMedium::new(vec![slab, semi], 1.0, 1.0).is_ok());
    }

    #[test]
    fn reduced_scattering_is_divided_by_one_minus_g() {
        let l = Layer::from_reduced(0.01, 1.0, 0.9, 1.4, None).unwrap();
        assert!((l.sigma_s() - 10.0).abs() < 1e-12);
    }
}
