//! The oblique-incidence gain over a box of skin parameters (docs/physics.md §19.3, "The angular
//! factor at each end"): one [`IncidenceGain`] per node of a grid over (C_m, β_m, C_h), each with
//! its normalisation c(λ), interpolated multilinearly at a texel's parameters with the profile
//! grid's weights (linear in each axis's warped coordinate, [`super::grid::node_weights`]). The
//! grid is built by `crate::fidelity::incidence`, which chooses its resolution from the
//! interpolation error it measures.

use super::grid::{node_weights, warped_axes};
use super::incidence::IncidenceGain;
use super::separable::Directional;
use crate::spectrum::{N_WAVELENGTHS, SampledSpectrum, SampledWavelengths};
use rayon::prelude::*;
use std::sync::Arc;

/// The angular factor of the separable BSSRDF at the nodes of a grid over (C_m, β_m, C_h).
#[derive(Debug, Clone)]
pub struct IncidenceGrid {
    /// Node values of each axis (C_m, β_m, C_h), increasing.
    axes: [Vec<f32>; 3],
    /// The same nodes warped, where the interpolation weights are linear.
    warped: [Vec<f32>; 3],
    /// The material's angular factor with each node's gain, C_m fastest.
    nodes: Vec<Directional>,
    /// The largest relative error of the interpolated a(μ, λ) or c(λ) against gains built
    /// directly, measured at the cells' centres when the grid was built.
    pub max_error: f32,
}

/// Up to eight nodes of an [`IncidenceGrid`] and their multilinear weights.
#[derive(Debug, Clone, Copy)]
pub struct GainCorners<'a> {
    grid: &'a IncidenceGrid,
    nodes: [(u32, f32); 8],
    n: usize,
}

impl IncidenceGrid {
    /// The grid over node values `axes` of the gains `gains` (C_m fastest), each put on the
    /// surface of `directional` (its T(μ) and split; its own gain, if any, is replaced);
    /// `max_error` as measured.
    ///
    /// # Panics
    /// If the gain count is not the product of the axes' lengths or an axis is empty.
    #[must_use]
    pub fn new(
        axes: [Vec<f32>; 3],
        directional: &Directional,
        gains: Vec<Arc<IncidenceGain>>,
        max_error: f32,
    ) -> Self {
        assert!(axes.iter().all(|a| !a.is_empty()), "every axis has a node");
        assert_eq!(
            gains.len(),
            axes.iter().map(Vec::len).product::<usize>(),
            "one gain per node"
        );
        let nodes = gains
            .into_par_iter()
            .map(|g| directional.clone().with_incidence(g))
            .collect();
        Self {
            warped: warped_axes(&axes),
            axes,
            nodes,
            max_error,
        }
    }

    /// [`Self::new`] with each node's normalisation rows `c` (as [`Self::nodes`] gave them
    /// for the same surface and split), or `None` if their count or length is not the gains', a
    /// gain is not whole or the gains' angles differ.
    #[must_use]
    pub fn with_rows(
        axes: [Vec<f32>; 3],
        directional: &Directional,
        gains: Vec<(Arc<IncidenceGain>, Vec<f32>)>,
        max_error: f32,
    ) -> Option<Self> {
        let count: usize = axes.iter().map(Vec::len).product();
        if axes.iter().any(Vec::is_empty)
            || gains.len() != count
            || gains
                .iter()
                .any(|(g, c)| !g.is_whole() || c.len() != g.wavelengths())
            || gains.windows(2).any(|w| w[0].0.angles() != w[1].0.angles())
        {
            return None;
        }
        let nodes = gains
            .into_iter()
            .map(|(g, c)| directional.clone().with_normalised_incidence(g, c))
            .collect();
        Some(Self {
            warped: warped_axes(&axes),
            axes,
            nodes,
            max_error,
        })
    }

    /// Every node's angular factor (its gain and normalisation rows), C_m fastest.
    #[must_use]
    pub fn nodes(&self) -> &[Directional] {
        &self.nodes
    }

    /// The node values of each axis (C_m, β_m, C_h).
    #[must_use]
    pub fn axes(&self) -> &[Vec<f32>; 3] {
        &self.axes
    }

    /// The nodes around parameters `p` = (C_m, β_m, C_h) and their weights.
    #[must_use]
    #[inline]
    pub fn corners(&self, p: [f32; 3]) -> GainCorners<'_> {
        let (nodes, n) = node_weights(&self.axes, &self.warped, p);
        GainCorners {
            grid: self,
            nodes,
            n,
        }
    }
}

impl GainCorners<'_> {
    /// The corners' angular factors and weights.
    fn nodes(&self) -> impl Iterator<Item = (&Directional, f32)> + '_ {
        self.nodes[..self.n]
            .iter()
            .map(|&(i, w)| (&self.grid.nodes[i as usize], w))
    }

    /// T(cos θ) a(cos θ, λ) at each of the path's wavelengths, a interpolated between the
    /// corners (T is the material's; 0 for cos ≤ 0).
    #[must_use]
    pub fn factors(&self, cos_theta: f32, wl: &SampledWavelengths) -> SampledSpectrum {
        let first = &self.grid.nodes[self.nodes[0].0 as usize];
        let t = first.transmittance(cos_theta);
        let Some(gain) = first.incidence().filter(|_| t > 0.0) else {
            return SampledSpectrum::splat(t);
        };
        // Every node's gain is tabulated at the same quadrature angles.
        let column = gain.column(cos_theta.min(1.0));
        let mut a = [0.0f32; N_WAVELENGTHS];
        for (d, w) in self.nodes() {
            if let Some(g) = d.incidence() {
                for (k, a) in a.iter_mut().enumerate() {
                    *a += w * g.gain_lane(column, wl, k);
                }
            }
        }
        SampledSpectrum(a.map(|a| t * a))
    }

    /// c(λ) = ∫₀¹ T(μ) a(μ, λ) 2μ dμ at each of the path's wavelengths, interpolated between
    /// the corners (c is linear in a).
    #[must_use]
    pub fn normalisations(&self, wl: &SampledWavelengths) -> SampledSpectrum {
        let mut c = [0.0f32; N_WAVELENGTHS];
        for (d, w) in self.nodes() {
            for (k, c) in c.iter_mut().enumerate() {
                *c += w * d.normalisation_lane(wl, k);
            }
        }
        SampledSpectrum(c)
    }
}

/// The separable BSSRDF's angular factor at one point (docs/physics.md §8.1, §19.3): the
/// material's, or the texel's of a skin with maps.
#[derive(Debug, Clone, Copy)]
pub enum AngularFactor<'a> {
    /// The material's, from its one skin.
    Material(&'a Directional),
    /// The texel's, from the incidence gain's grid.
    Texel(GainCorners<'a>),
}

impl AngularFactor<'_> {
    /// T(cos θ) a(cos θ, λ) at each of the path's wavelengths.
    #[must_use]
    pub fn factors(&self, cos_theta: f32, wl: &SampledWavelengths) -> SampledSpectrum {
        match self {
            Self::Material(d) => d.factors(cos_theta, wl),
            Self::Texel(g) => g.factors(cos_theta, wl),
        }
    }

    /// c = ∫₀¹ T(μ) 2μ dμ of the surface alone, without the gain ([`Directional::normalisation`]).
    #[must_use]
    pub fn normalisation(&self) -> f32 {
        match self {
            Self::Material(d) => d.normalisation(),
            Self::Texel(g) => g.grid.nodes[g.nodes[0].0 as usize].normalisation(),
        }
    }

    /// c(λ) at each of the path's wavelengths.
    #[must_use]
    pub fn normalisations(&self, wl: &SampledWavelengths) -> SampledSpectrum {
        match self {
            Self::Material(d) => {
                SampledSpectrum(std::array::from_fn(|k| d.normalisation_lane(wl, k)))
            }
            Self::Texel(g) => g.normalisations(wl),
        }
    }
}
