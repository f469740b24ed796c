//! Churning of one loss entry (a gear with all its immersions, e.g. a planet's orbit-average
//! nodes) for one drive-cycle sample: with the Changenet–Velex model, a law of the oil alone
//! built when the sample's speed is known ([`ChangenetSum`]), which every right-hand side of the
//! sample evaluates with at most one exponential (more only inside the bridge band between the
//! two laws). The other churning models are evaluated model by model.

use crate::physics::losses::churning::{
    ChangenetAtSpeed, ChangenetSum, GearChurning, OilState, STANDSTILL_RAD_S,
};

/// The sum law of an entry's models when they are all Changenet–Velex immersions of one gear.
pub fn sum_law(models: &[(GearChurning, f64)]) -> Option<ChangenetSum> {
    let parts: Option<Vec<_>> = models
        .iter()
        .map(|(m, w)| match m {
            GearChurning::Changenet(g) => Some((*g, *w)),
            _ => None,
        })
        .collect();
    ChangenetSum::new(&parts?)
}

/// One churning entry's state for the current sample.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub enum ChurnSample {
    /// Evaluate every model at the speed.
    #[default]
    Direct,
    /// Standstill: no churning.
    Still,
    /// The entry's sum law at the sample's speed.
    Law(ChangenetAtSpeed),
}

impl ChurnSample {
    /// The sample's state for an entry with sum law `law` at speed `omega` (rad/s).
    pub fn prepare(law: Option<&ChangenetSum>, omega: f64) -> Self {
        match law {
            _ if omega.abs() < STANDSTILL_RAD_S => ChurnSample::Still,
            Some(l) => ChurnSample::Law(l.at_speed(omega)),
            None => ChurnSample::Direct,
        }
    }

    /// Churning power (W) of `models` (sum law `law`) at speed `omega` and oil `oil`, with
    /// `ln_nu` = ln ν.
    pub fn power(
        &self,
        models: &[(GearChurning, f64)],
        law: Option<&ChangenetSum>,
        omega: f64,
        oil: &OilState,
        ln_nu: f64,
    ) -> f64 {
        match (self, law) {
            (ChurnSample::Still, _) => 0.0,
            (ChurnSample::Law(s), Some(l)) => oil.density * l.power_per_density(s, ln_nu),
            _ => models.iter().map(|(m, wt)| wt * m.power(omega, oil).total).sum(),
        }
    }
}
