//! The gear table the cycle layer works with: the model's gear states and their ratios, bound
//! by name. Its own module so that `vehicle`, `shift`, `launch` and `schedule` all depend on it
//! and not on each other in a circle (`schedule` → `shift` → `vehicle` → `gears`).

/// The model's gear states with their ratios ω_in/ω_out (reverse negative).
#[derive(Debug, Clone, PartialEq)]
pub struct GearTable {
    /// (name, ratio) per gear state.
    pub states: Vec<(String, f64)>,
}

impl GearTable {
    /// Wrap a list of (name, ratio).
    pub fn new(states: Vec<(String, f64)>) -> Self {
        GearTable { states }
    }

    /// Index of the state named `name`.
    pub fn index_of(&self, name: &str) -> Option<usize> {
        self.states.iter().position(|(n, _)| n == name)
    }

    /// All state names.
    pub fn names(&self) -> Vec<&str> {
        self.states.iter().map(|(n, _)| n.as_str()).collect()
    }
}

impl From<Vec<(String, f64)>> for GearTable {
    fn from(states: Vec<(String, f64)>) -> Self {
        GearTable { states }
    }
}
