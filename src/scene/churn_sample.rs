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

/// The per-sample powers of the input speed that churning laws share: ln ω_in, and ω_in raised to
/// the last pair of law exponents asked for (the examples' gears all share one pair).
pub struct InputSpeedPowers {
    ln_w: f64,
    memo: ([f64; 2], [f64; 2]),
}

impl InputSpeedPowers {
    /// For input speed `w_in` (rad/s).
    pub fn new(w_in: f64) -> Self {
        InputSpeedPowers {
            ln_w: w_in.abs().ln(),
            memo: ([f64::NAN; 2], [0.0; 2]),
        }
    }

    fn powers(&mut self, e: [f64; 2]) -> [f64; 2] {
        if self.memo.0 != e {
            self.memo = (e, e.map(|x| (x * self.ln_w).exp()));
        }
        self.memo.1
    }
}

impl ChurnSample {
    /// The sample's state for an entry with sum law `law` (and its `ratio_terms` for the gear
    /// state) whose gear turns at `omega` (rad/s) = ratio × the input speed of `input`.
    pub fn prepare(
        law: Option<&ChangenetSum>,
        ratio_terms: &[f64; 3],
        omega: f64,
        input: &mut InputSpeedPowers,
    ) -> Self {
        match law {
            _ if omega.abs() < STANDSTILL_RAD_S => ChurnSample::Still,
            Some(l) => {
                let p = input.powers(l.speed_exponents());
                ChurnSample::Law(l.at_ratio(ratio_terms, input.ln_w, p))
            }
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
