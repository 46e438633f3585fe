//! Exact per-layer totals of the two-layer skin, for rescaling each diffusion layer before stacking
//! (`crate::skin`): the epidermis alone (air above, index matched below) seen from above
//! and from below, the semi-infinite dermis alone, and the whole stack, from one set of operators.
//!
//! Each layer's scalar is taken for the angular distribution that layer actually meets first in the
//! stack: R↓, T↓ of the epidermis for the normally incident beam (per flux entering), R of the dermis
//! for the flux the epidermis transmits, R↑, T↑ of the epidermis for the flux the dermis sends back up.

use super::layer::Operator;
use super::matrix::Mat;
use super::{AddingDoublingError, AddingDoublingOptions, angles, build_layer, escape_through_top};
use crate::error::MultipoleError;
use crate::layered::LayeredMedium;
use skin_optics::{SkinParams, Wavelength};

/// Exact totals of each skin layer alone and of the stack (dimensionless, per unit flux entering
/// the skin unless stated).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LayerTotals {
    /// Epidermis R↓: diffuse flux leaving through the top for the normal beam that entered.
    pub epidermis_r_down: f64,
    /// Epidermis T↓: flux leaving the bottom (scattered and unscattered) for the normal beam that entered.
    pub epidermis_t_down: f64,
    /// Epidermis R↑: flux sent back down, for the flux the dermis returns upward.
    pub epidermis_r_up: f64,
    /// Epidermis T↑: flux escaping to the air, for the flux the dermis returns upward.
    pub epidermis_t_up: f64,
    /// Dermis R (semi-infinite, index matched above) for the flux the epidermis transmits.
    pub dermis_r: f64,
    /// The whole skin's total diffuse reflectance per unit flux entering (what
    /// `skin_total_reflectance` returns).
    pub total: f64,
}

fn sum(v: &[f64]) -> f64 {
    v.iter().sum()
}

/// Per-layer and total exact transport of the skin at `lambda` (module doc).
pub fn skin_layer_totals(
    skin: &SkinParams,
    lambda: Wavelength,
    options: &AddingDoublingOptions,
) -> Result<LayerTotals, MultipoleError> {
    let medium = LayeredMedium::skin(skin, lambda, options.g())?;
    let eta = skin.eta();
    let angles = angles(&medium, eta, options.quadrature_points());
    let normal = angles.n() - 1;
    let top = super::layer::interface(&angles, &medium.surface().reflector(eta, medium.n_above()));
    let layers = medium.layers();
    let epidermis = build_layer(&angles, &layers[0])?;
    let dermis = build_layer(&angles, &layers[1])?;
    let entering = top.t_down[(normal, normal)];
    // The epidermis under its air interface, nothing below (matched index: what leaves the bottom is gone).
    let upper: Operator = top
        .add(&epidermis)
        .map_err(|_| AddingDoublingError::Singular("adding the top surface"))?;
    let r_down = (upper.r_down.column_sum(normal) - top.r_down[(normal, normal)]) / entering;
    let transmitted: Vec<f64> = upper
        .t_down
        .column(normal)
        .iter()
        .map(|v| v / entering)
        .collect();
    let t_down = sum(&transmitted);
    let returned = dermis.r_down.mul_vec(&transmitted);
    let dermis_r = sum(&returned) / t_down;
    let up_norm = sum(&returned);
    let r_up = sum(&upper.r_up.mul_vec(&returned)) / up_norm;
    let t_up = sum(&upper.t_up.mul_vec(&returned)) / up_norm;
    let below: Mat = epidermis
        .reflect_over(&dermis.r_down)
        .map_err(|_| AddingDoublingError::Singular("adding layers"))?;
    let total = escape_through_top(&top, &below, normal)? / entering;
    Ok(LayerTotals {
        epidermis_r_down: r_down,
        epidermis_t_down: t_down,
        epidermis_r_up: r_up,
        epidermis_t_up: t_up,
        dermis_r,
        total,
    })
}
