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

use std::fmt;

/// Errors of the thermal model: every message names the item and value at fault.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ThermalError {
    /// A layer stack has no layers.
    #[error("thermal layer stack is empty: give at least one layer")]
    EmptyStack,
    /// A layer's material or thickness is not a positive finite number.
    #[error("thermal layer {index} ('{name}'): {quantity} must be positive and finite, got {value} {unit}")]
    InvalidLayer {
        /// 1-based position of the layer from the front.
        index: usize,
        /// Name of the layer's material.
        name: String,
        /// Which quantity is wrong.
        quantity: &'static str,
        /// The value given.
        value: f64,
        /// Its unit.
        unit: &'static str,
    },
    /// A grid resolution parameter is out of range.
    #[error("thermal grid: {0}")]
    InvalidResolution(String),
    /// A forcing, boundary or control value is out of range.
    #[error("thermal solver: {0}")]
    InvalidInput(String),
    /// The implicit step produced no physical surface temperature.
    #[error("thermal solver: {0}")]
    NoSolution(String),
}

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
    /// Validates every layer: k, ρ, c and d must be positive and finite.
    pub fn new(layers: Vec<Layer>) -> Result<Self, ThermalError> {
        if layers.is_empty() {
            return Err(ThermalError::EmptyStack);
        }
        for (i, layer) in layers.iter().enumerate() {
            let m = &layer.material;
            let checks = [
                ("thickness", layer.thickness_m, "m"),
                ("conductivity", m.conductivity_w_mk, "W/m/K"),
                ("density", m.density_kg_m3, "kg/m^3"),
                ("heat capacity", m.heat_capacity_j_kgk, "J/kg/K"),
            ];
            for (quantity, value, unit) in checks {
                if !(value.is_finite() && value > 0.0) {
                    return Err(ThermalError::InvalidLayer {
                        index: i + 1,
                        name: m.name.clone(),
                        quantity,
                        value,
                        unit,
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
            let widths = layer_cells(layer.thickness_m, next, resolution);
            next = widths.last().copied().unwrap_or(next) * resolution.growth;
            cells.extend(widths.into_iter().map(|w| (w, li)));
        }
        Ok(Grid::from_cells(&self.layers, &cells))
    }
}

/// Cells of one layer: geometric from `start` (capped at d/min_cells), scaled to fill d exactly.
fn layer_cells(d: f64, start: f64, res: &Resolution) -> Vec<f64> {
    let cap = d / res.min_cells as f64;
    let mut w = start.min(cap);
    let mut widths = Vec::new();
    let mut sum = 0.0;
    while sum < d * (1.0 - 1e-12) {
        widths.push(w);
        sum += w;
        w = (w * res.growth).min(cap);
    }
    // Scaling down (sum ≥ d) keeps every cell within the rule.
    let scale = d / sum;
    widths.iter_mut().for_each(|w| *w *= scale);
    widths
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
    /// §1.8's 0.01 K (tests/thermal_solver.rs); a thin painted panel is within 0.001 K either way.
    fn default() -> Self {
        Self {
            first_cell_m: 2e-4,
            growth: 1.1,
            min_cells: 3,
        }
    }
}

impl Resolution {
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
                self.first_cell_m
            )));
        }
        if !(self.growth.is_finite() && self.growth > 1.0 && self.growth <= 2.0) {
            return Err(ThermalError::InvalidResolution(format!(
                "growth must be in (1, 2], got {}",
                self.growth
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
            text.contains("conductivity") && text.contains("-0.04"),
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
