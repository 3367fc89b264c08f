//! Degrees of freedom in Fossen's notation (SNAME): body velocities
//! ν = [u v w p q r]ᵀ and generalized forces τ = [X Y Z K M N]ᵀ.

use std::collections::BTreeMap;

use serde::{Deserialize, Deserializer, Serialize};

/// One degree of freedom of the vessel.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
#[cfg_attr(feature = "openapi", derive(utoipa::ToSchema))]
#[serde(rename_all = "lowercase")]
pub enum Dof {
    /// Surge: u (m/s), X (N).
    Surge,
    /// Sway: v (m/s), Y (N).
    Sway,
    /// Heave: w (m/s), Z (N).
    Heave,
    /// Roll: p (rad/s), K (N·m).
    Roll,
    /// Pitch: q (rad/s), M (N·m).
    Pitch,
    /// Yaw: r (rad/s), N (N·m).
    Yaw,
}

impl Dof {
    /// All six DOFs in Fossen's order.
    pub const ALL: [Dof; 6] = [
        Dof::Surge,
        Dof::Sway,
        Dof::Heave,
        Dof::Roll,
        Dof::Pitch,
        Dof::Yaw,
    ];
    /// The horizontal-plane DOFs of a DP surface vessel's low-frequency model.
    pub const HORIZONTAL: [Dof; 3] = [Dof::Surge, Dof::Sway, Dof::Yaw];

    /// Index in ν (0..6).
    pub fn index(self) -> usize {
        self as usize
    }

    /// The DOF of a lower-case name.
    pub fn from_name(name: &str) -> Option<Dof> {
        Dof::ALL.into_iter().find(|d| d.name() == name)
    }

    /// Lower-case name as used in JSON and messages.
    pub fn name(self) -> &'static str {
        ["surge", "sway", "heave", "roll", "pitch", "yaw"][self.index()]
    }

    /// Body-velocity symbol in ν (log column name).
    pub fn velocity_symbol(self) -> &'static str {
        ["u", "v", "w", "p", "q", "r"][self.index()]
    }

    /// The velocity symbols of `dofs`, in order: a model's output names.
    pub fn velocity_symbols(dofs: &[Dof]) -> Vec<String> {
        dofs.iter()
            .map(|d| d.velocity_symbol().to_string())
            .collect()
    }

    /// Generalized-force log column name (`tau_X` …).
    pub fn force_column(self) -> &'static str {
        ["tau_X", "tau_Y", "tau_Z", "tau_K", "tau_M", "tau_N"][self.index()]
    }

    /// Rotational DOF (roll, pitch, yaw): velocities in rad/s, forces in N·m.
    pub fn is_angular(self) -> bool {
        self.index() >= 3
    }

    /// SI unit of the velocity.
    pub fn velocity_unit(self) -> &'static str {
        if self.is_angular() { "rad/s" } else { "m/s" }
    }

    /// SI unit of the generalized force.
    pub fn force_unit(self) -> &'static str {
        if self.is_angular() { "N·m" } else { "N" }
    }
}

/// Deserializes a map keyed by DOF name. Keys are read as strings first so
/// that an error inside a value is reported at `limits.sway.max_force`, not
/// at an anonymous key.
pub fn deserialize_dof_map<'de, D, T>(d: D) -> Result<BTreeMap<Dof, T>, D::Error>
where
    D: Deserializer<'de>,
    T: Deserialize<'de>,
{
    BTreeMap::<String, T>::deserialize(d)?
        .into_iter()
        .map(|(k, v)| {
            Dof::from_name(&k).map(|dof| (dof, v)).ok_or_else(|| {
                serde::de::Error::custom(format!(
                    "unknown DOF '{k}'; expected surge, sway, heave, roll, pitch or yaw"
                ))
            })
        })
        .collect()
}

/// Knots to metres per second (1 kn = 1852 m / 3600 s).
pub const KNOT: f64 = 1852.0 / 3600.0;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_and_columns_follow_fossen() {
        assert_eq!(Dof::Yaw.velocity_symbol(), "r");
        assert_eq!(Dof::Pitch.force_column(), "tau_M");
        assert!(Dof::Roll.is_angular() && !Dof::Heave.is_angular());
        let json = serde_json::to_string(&Dof::Sway).unwrap();
        assert_eq!(json, "\"sway\"");
    }

    #[test]
    fn knot_is_exact() {
        assert!((KNOT - 0.514_444_444_444_444_4).abs() < 1e-15);
    }
}
