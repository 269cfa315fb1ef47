//! Layer materials, layer stacks and their 1-D finite-volume grid (docs/design.md §1.8).
//!
//! A vertex's stack runs from the exposed front surface to the back face; layers are in perfect
//! contact and only conduct along the normal (no lateral conduction, §1.8).
//!
//! **Grid (vertex-centred finite volumes).** Nodes sit on the front surface, on every layer
//! interface and on the back face, plus interior nodes. Each node owns half of each cell next to it,
//! so its heat capacity is Σ ρc·Δx/2 over those half cells, and two neighbours are linked by the
//! conductance k/Δx of the one cell between them. A node on an interface therefore couples the two
//! materials through the series resistance of the two half cells — the harmonic mean of the
//! conductances — which is exact for perfect contact and makes a linear steady profile exact. A node
//! *on* the front surface (not half a cell below it) is what the surface energy balance and the
//! image need: T_s is a node temperature, not an extrapolation.
//!
//! **Spacing rule.** Cells grow geometrically from the front: the first cell is at most
//! [`Resolution::first_cell_m`] and each further cell is at most [`Resolution::growth`] times the
//! one before, across layer interfaces too, and no cell is thicker than its layer / `min_cells`
//! (so a thin paint layer gets at least `min_cells` cells however thin it is). A layer's cells are
//! then scaled down uniformly so they fill it exactly. Fine cells are needed at the front because
//! that is where the forcing changes fastest (the penetration depth √(αΔt) of a one-minute change
//! is ~2 mm in paint); deep cells can be coarse because the diurnal signal there is smooth.

use crate::optics::MAX_TEMPERATURE_K;
use crate::text::number;
use std::fmt;

/// Errors of the thermal model: every message names the item and value at fault, once (the
/// caller adds which part and when, not the same words again).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ThermalError {
    /// A layer stack has no layers.
    #[error("the layer stack is empty: give at least one layer")]
    EmptyStack,
    /// A layer's material or thickness is outside [`LAYER_LIMITS`].
    #[error(
        "layer {index} ('{name}'): {quantity} = {} {unit} is outside {}…{} {unit} ({why})",
        number(*value), number(LAYER_LIMITS[*limit].min), number(LAYER_LIMITS[*limit].max),
        quantity = LAYER_LIMITS[*limit].quantity, unit = LAYER_LIMITS[*limit].unit,
        why = LAYER_LIMITS[*limit].spans
    )]
    InvalidLayer {
        /// 1-based position of the layer from the front.
        index: usize,
        /// Name of the layer's material.
        name: String,
        /// The value given.
        value: f64,
        /// Which of [`LAYER_LIMITS`] it breaks.
        limit: usize,
    },
    /// The stack's grid would have more nodes than [`MAX_GRID_NODES`].
    #[error(
        "the layer stack needs more than {MAX_GRID_NODES} grid nodes under this resolution: use \
         fewer or thicker layers"
    )]
    TooManyNodes,
    /// A grid resolution parameter is out of range.
    #[error("grid resolution: {0}")]
    InvalidResolution(String),
    /// A forcing, boundary or control value is out of range.
    #[error("{0}")]
    InvalidInput(String),
    /// No positive surface temperature balances the step: more heat leaves than the layers hold.
    #[error(
        "no positive surface temperature balances the heat flows (more heat is drawn out than \
         the layers hold): check internal_heat_w_m2 and the back boundary"
    )]
    NoSurfaceTemperature,
    /// The scalar surface balance did not converge.
    #[error("the surface balance did not converge in {iterations} Newton iterations (last {} K)", number(*last_k))]
    NewtonDiverged { iterations: usize, last_k: f64 },
    /// The adaptive sub-steps did not meet their tolerance within the cap of sub-steps.
    #[error(
        "the time step of {} s did not converge in {substeps} sub-steps (surface at {} K): the \
         layers or the forcing are too extreme for the solver (see the thermal limits in \
         docs/thermal.md)",
        number(*step_s), number(*surface_k)
    )]
    NotConverged {
        step_s: f64,
        substeps: usize,
        surface_k: f64,
    },
    /// A node temperature left (0, MAX_TEMPERATURE_K]: the forcing is beyond what the model holds.
    #[error(
        "a temperature reached {} K, outside (0, {MAX_TEMPERATURE_K}] K: the forcing (irradiance, \
         internal heat, convection) is beyond what the model represents",
        number(*temperature_k)
    )]
    Runaway { temperature_k: f64 },
}

/// The accepted range of one layer quantity.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LayerLimit {
    pub quantity: &'static str,
    pub unit: &'static str,
    pub min: f64,
    pub max: f64,
    /// What the range spans, for the message.
    pub spans: &'static str,
}

/// The accepted range of thickness, conductivity, density and heat capacity, in that order.
/// Beyond them the model is not a model of anything (a 5e-324 m layer, a 1e12 W/m/K conductor),
/// the grid stops being small and the implicit steps lose every digit to round-off.
pub const LAYER_LIMITS: [LayerLimit; 4] = [
    LayerLimit {
        quantity: "thickness",
        unit: "m",
        min: 1e-6,
        max: 100.0,
        spans: "a micrometre film to 100 m of ground",
    },
    LayerLimit {
        quantity: "conductivity",
        unit: "W/m/K",
        min: 1e-3,
        max: 1e4,
        spans: "below aerogel to above diamond",
    },
    LayerLimit {
        quantity: "density",
        unit: "kg/m^3",
        min: 0.1,
        max: 1e5,
        spans: "thin gas to above osmium",
    },
    LayerLimit {
        quantity: "heat capacity",
        unit: "J/kg/K",
        min: 10.0,
        max: 1e5,
        spans: "below lead to above hydrogen",
    },
];

/// Most nodes of one stack's grid: the default resolution gives a thin panel ~30 nodes and 100 m
/// of ground ~130; each node costs a few doubles per distinct solve.
pub const MAX_GRID_NODES: usize = 10_000;

/// Thermal properties of one layer material.
#[derive(Debug, Clone, PartialEq)]
pub struct LayerMaterial {
    /// Name used in error messages.
    pub name: String,
    /// Conductivity k (W m⁻¹ K⁻¹).
    pub conductivity_w_mk: f64,
    /// Density ρ (kg m⁻³).
    pub density_kg_m3: f64,
    /// Specific heat capacity c (J kg⁻¹ K⁻¹).
    pub heat_capacity_j_kgk: f64,
}

impl LayerMaterial {
    /// A material; validated when it is put into a [`LayerStack`].
    pub fn new(
        name: &str,
        conductivity_w_mk: f64,
        density_kg_m3: f64,
        heat_capacity_j_kgk: f64,
    ) -> Self {
        Self {
            name: name.to_string(),
            conductivity_w_mk,
            density_kg_m3,
            heat_capacity_j_kgk,
        }
    }

    /// Volumetric heat capacity ρc (J m⁻³ K⁻¹).
    pub fn volumetric_heat_capacity(&self) -> f64 {
        self.density_kg_m3 * self.heat_capacity_j_kgk
    }

    /// Thermal diffusivity α = k/(ρc) (m² s⁻¹).
    pub fn diffusivity_m2_s(&self) -> f64 {
        self.conductivity_w_mk / self.volumetric_heat_capacity()
    }
}

/// One layer: a material and its thickness.
#[derive(Debug, Clone, PartialEq)]
pub struct Layer {
    /// The material.
    pub material: LayerMaterial,
    /// Thickness d (m).
    pub thickness_m: f64,
}

impl Layer {
    /// A layer of `thickness_m` metres of `material`.
    pub fn new(material: LayerMaterial, thickness_m: f64) -> Self {
        Self {
            material,
            thickness_m,
        }
    }
}

/// A validated stack of layers, front (exposed) first.
#[derive(Debug, Clone, PartialEq)]
pub struct LayerStack {
    layers: Vec<Layer>,
}

impl LayerStack {
    /// Validates every layer: d, k, ρ and c finite and within [`LAYER_LIMITS`].
    pub fn new(layers: Vec<Layer>) -> Result<Self, ThermalError> {
        if layers.is_empty() {
            return Err(ThermalError::EmptyStack);
        }
        for (i, layer) in layers.iter().enumerate() {
            let m = &layer.material;
            let values = [
                layer.thickness_m,
                m.conductivity_w_mk,
                m.density_kg_m3,
                m.heat_capacity_j_kgk,
            ];
            for (limit, (value, range)) in values.into_iter().zip(LAYER_LIMITS).enumerate() {
                if !(range.min..=range.max).contains(&value) {
                    return Err(ThermalError::InvalidLayer {
                        index: i + 1,
                        name: m.name.clone(),
                        value,
                        limit,
                    });
                }
            }
        }
        Ok(Self { layers })
    }

    /// The layers, front first.
    pub fn layers(&self) -> &[Layer] {
        &self.layers
    }

    /// Total thickness (m).
    pub fn thickness_m(&self) -> f64 {
        self.layers.iter().map(|l| l.thickness_m).sum()
    }

    /// Conductive resistance front to back, R = Σ dᵢ/kᵢ (m² K W⁻¹).
    pub fn resistance_m2k_w(&self) -> f64 {
        self.layers
            .iter()
            .map(|l| l.thickness_m / l.material.conductivity_w_mk)
            .sum()
    }

    /// Heat capacity per unit area, Σ ρᵢcᵢdᵢ (J m⁻² K⁻¹).
    pub fn heat_capacity_j_m2k(&self) -> f64 {
        self.layers
            .iter()
            .map(|l| l.material.volumetric_heat_capacity() * l.thickness_m)
            .sum()
    }

    /// The finite-volume grid of this stack under the spacing rule of the module docs.
    pub fn discretise(&self, resolution: &Resolution) -> Result<Grid, ThermalError> {
        resolution.validate()?;
        let mut cells: Vec<(f64, usize)> = Vec::new(); // (width, layer index)
        let mut next = resolution.first_cell_m;
        for (li, layer) in self.layers.iter().enumerate() {
            let budget = MAX_GRID_NODES - 1 - cells.len();
            let widths = layer_cells(layer.thickness_m, next, resolution, budget)?;
            next = widths.last().copied().unwrap_or(next) * resolution.growth;
            cells.extend(widths.into_iter().map(|w| (w, li)));
        }
        Ok(Grid::from_cells(&self.layers, &cells))
    }
}

/// Cells of one layer: geometric from `start` (capped at d/min_cells), scaled to fill d exactly;
/// refused beyond `budget` cells, which a fine [`Resolution`] over many layers can reach.
fn layer_cells(
    d: f64,
    start: f64,
    res: &Resolution,
    budget: usize,
) -> Result<Vec<f64>, ThermalError> {
    let cap = d / res.min_cells as f64;
    let mut w = start.min(cap);
    let mut widths = Vec::new();
    let mut sum = 0.0;
    while sum < d * (1.0 - 1e-12) {
        if widths.len() >= budget {
            return Err(ThermalError::TooManyNodes);
        }
        widths.push(w);
        sum += w;
        w = (w * res.growth).min(cap);
    }
    // Scaling down (sum ≥ d) keeps every cell within the rule.
    let scale = d / sum;
    widths.iter_mut().for_each(|w| *w *= scale);
    Ok(widths)
}

/// Grid spacing controls (see the module docs for the rule).
#[derive(Debug, Clone, PartialEq)]
pub struct Resolution {
    /// Largest first cell at the front surface (m).
    pub first_cell_m: f64,
    /// Largest ratio between a cell and the one in front of it (> 1).
    pub growth: f64,
    /// Fewest cells in any layer.
    pub min_cells: usize,
}

impl Default for Resolution {
    /// 0.2 mm first cell, 10 % growth, 3 cells per layer. The growth ratio sets the error (the
    /// vertex-centred scheme is second order in growth − 1): with 20 % a 0.3 m concrete slab under
    /// diurnal forcing was 0.02 K from the converged surface temperature, with 10 % 0.005 K, inside
    /// §1.8's 0.01 K (tests/it/thermal_solver.rs); a thin painted panel is within 0.001 K either way.
    fn default() -> Self {
        Self {
            first_cell_m: 2e-4,
            growth: 1.1,
            min_cells: 3,
        }
    }
}

impl Resolution {
    /// The grid of the batched fixed-step solver (`batch`): the default with a 1 mm first cell.
    /// Its sub-steps of a minute cannot resolve what finer surface cells carry (a minute's
    /// diffusion length in soil or asphalt is ~6 mm); thin layers keep their `min_cells`. On
    /// asphalt over soil this is 44 nodes instead of 61, 1.0 mK from the adaptive solution on the
    /// default grid on average over a day (0.5 mK on the default grid; tests/it/thermal_batch.rs).
    pub fn batch() -> Self {
        Self {
            first_cell_m: 1e-3,
            ..Self::default()
        }
    }

    /// A grid `factor` times finer: first cell / factor, growth^(1/factor), min_cells × factor.
    pub fn refined(&self, factor: usize) -> Self {
        Self {
            first_cell_m: self.first_cell_m / factor as f64,
            growth: self.growth.powf(1.0 / factor as f64),
            min_cells: self.min_cells * factor,
        }
    }

    fn validate(&self) -> Result<(), ThermalError> {
        if !(self.first_cell_m.is_finite() && self.first_cell_m > 0.0) {
            return Err(ThermalError::InvalidResolution(format!(
                "first_cell_m must be positive and finite, got {}",
                number(self.first_cell_m)
            )));
        }
        if !(self.growth.is_finite() && self.growth > 1.0 && self.growth <= 2.0) {
            return Err(ThermalError::InvalidResolution(format!(
                "growth must be in (1, 2], got {}",
                number(self.growth)
            )));
        }
        if !(1..=1000).contains(&self.min_cells) {
            return Err(ThermalError::InvalidResolution(format!(
                "min_cells must be in 1..=1000, got {}",
                self.min_cells
            )));
        }
        Ok(())
    }
}

/// The discretised stack: node depths, heat capacities and link conductances, all per unit area.
#[derive(Debug, Clone, PartialEq)]
pub struct Grid {
    depth_m: Vec<f64>,
    capacity: Vec<f64>,
    conductance: Vec<f64>,
}

impl Grid {
    fn from_cells(layers: &[Layer], cells: &[(f64, usize)]) -> Self {
        let n = cells.len() + 1;
        let mut depth_m = vec![0.0; n];
        let mut capacity = vec![0.0; n];
        let mut conductance = Vec::with_capacity(n - 1);
        for (i, &(w, li)) in cells.iter().enumerate() {
            let m = &layers[li].material;
            depth_m[i + 1] = depth_m[i] + w;
            let half = 0.5 * m.volumetric_heat_capacity() * w;
            capacity[i] += half;
            capacity[i + 1] += half;
            conductance.push(m.conductivity_w_mk / w);
        }
        Self {
            depth_m,
            capacity,
            conductance,
        }
    }

    /// Number of nodes (front surface is node 0, back face the last).
    pub fn len(&self) -> usize {
        self.depth_m.len()
    }

    /// Always false: a grid has at least two nodes.
    pub fn is_empty(&self) -> bool {
        self.depth_m.is_empty()
    }

    /// Node depths below the front surface (m).
    pub fn depths_m(&self) -> &[f64] {
        &self.depth_m
    }

    /// Node heat capacities Σ ρc Δx/2 (J m⁻² K⁻¹).
    pub fn capacities_j_m2k(&self) -> &[f64] {
        &self.capacity
    }

    /// Conductances k/Δx between node i and i+1 (W m⁻² K⁻¹).
    pub fn conductances_w_m2k(&self) -> &[f64] {
        &self.conductance
    }

    /// Heat stored relative to 0 K, Σ Cᵢ Tᵢ (J m⁻²); differences of it are ∫ρcΔT dx.
    pub fn heat_j_m2(&self, temperatures_k: &[f64]) -> f64 {
        self.capacity
            .iter()
            .zip(temperatures_k)
            .map(|(c, t)| c * t)
            .sum()
    }
}

impl fmt::Display for LayerStack {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (i, l) in self.layers.iter().enumerate() {
            if i > 0 {
                write!(f, " | ")?;
            }
            write!(f, "{} {} mm", l.material.name, l.thickness_m * 1e3)?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn steel() -> LayerMaterial {
        LayerMaterial::new("steel", 45.0, 7850.0, 470.0)
    }

    #[test]
    fn bad_layers_are_named_in_the_error() {
        let err = LayerStack::new(vec![
            Layer::new(steel(), 1e-3),
            Layer::new(LayerMaterial::new("foam", -0.04, 30.0, 1400.0), 0.02),
        ])
        .unwrap_err();
        let text = err.to_string();
        assert!(
            text.contains("layer 2") && text.contains("'foam'"),
            "{text}"
        );
        assert!(
            text.contains("conductivity = -0.04 W/m/K is outside 0.001…10000 W/m/K"),
            "{text}"
        );
        let err = LayerStack::new(vec![Layer::new(steel(), f64::NAN)]).unwrap_err();
        assert!(err.to_string().contains("thickness"), "{err}");
        let err = LayerStack::new(vec![Layer::new(
            LayerMaterial::new("x", 1.0, 1.0, 0.0),
            1.0,
        )]);
        assert!(err.unwrap_err().to_string().contains("heat capacity"));
        assert_eq!(LayerStack::new(vec![]), Err(ThermalError::EmptyStack));
        let stack = LayerStack::new(vec![Layer::new(steel(), 1e-3)]).unwrap();
        let bad = Resolution {
            growth: 1.0,
            ..Resolution::default()
        };
        assert!(stack
            .discretise(&bad)
            .unwrap_err()
            .to_string()
            .contains("growth"));
    }

    #[test]
    fn grid_follows_the_spacing_rule_and_conserves_capacity() {
        let paint = LayerMaterial::new("paint", 0.2, 1200.0, 1500.0);
        let stack = LayerStack::new(vec![
            Layer::new(paint, 1e-5),
            Layer::new(steel(), 1e-3),
            Layer::new(LayerMaterial::new("foam", 0.04, 30.0, 1400.0), 0.5),
        ])
        .unwrap();
        let res = Resolution::default();
        let grid = stack.discretise(&res).unwrap();
        let x = grid.depths_m();
        let widths: Vec<f64> = x.windows(2).map(|w| w[1] - w[0]).collect();
        assert!(widths[0] <= res.first_cell_m);
        for w in widths.windows(2) {
            assert!(w[1] <= w[0] * res.growth * (1.0 + 1e-9), "{w:?}");
        }
        // Every interface is a node, every layer has at least min_cells cells.
        let mut edge = 0.0;
        for layer in stack.layers() {
            let start = edge;
            edge += layer.thickness_m;
            assert!(x
                .iter()
                .any(|&xi| (xi - edge).abs() < 1e-12 * edge.max(1e-3)));
            let inside = widths
                .iter()
                .zip(x)
                .filter(|(_, &xi)| xi >= start - 1e-15 && xi < edge - 1e-15)
                .count();
            assert!(
                inside >= res.min_cells,
                "{} cells in {}",
                inside,
                layer.material.name
            );
        }
        assert!((x[x.len() - 1] - stack.thickness_m()).abs() < 1e-12);
        let cap: f64 = grid.capacities_j_m2k().iter().sum();
        assert!((cap - stack.heat_capacity_j_m2k()).abs() < 1e-9 * cap);
        let r: f64 = grid.conductances_w_m2k().iter().map(|g| 1.0 / g).sum();
        assert!((r - stack.resistance_m2k_w()).abs() < 1e-12 * r);
        assert!(grid.len() < 200, "{} nodes", grid.len());
    }
}
