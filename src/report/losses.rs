//! `geartherm losses`: every loss item at one operating point, per-source totals, efficiency.

use std::fmt::Write as _;

use serde::Serialize;

use crate::model::Gearbox;
use crate::scene::{sum_by_source, LossScene, OperatingPoint, RangeLog, RangeWarning, Skipped, Source};

use super::sources::SourceValues;

/// One loss item.
#[derive(Debug, Serialize)]
pub struct ItemReport {
    /// `churning`, `pocketing` or `sliding`.
    pub source: Source,
    /// Gear or mesh name.
    pub name: String,
    /// Power, W.
    pub w: f64,
}

/// The `losses` report.
#[derive(Debug, Serialize)]
pub struct LossReport {
    /// Model name.
    pub model: String,
    /// Gear state.
    pub gear: String,
    /// Input speed, rpm.
    pub input_speed_rpm: f64,
    /// Input torque, N·m.
    pub input_torque_nm: f64,
    /// Oil temperature, °C.
    pub oil_temp_c: f64,
    /// Kinematic viscosity at that temperature, cSt.
    pub oil_viscosity_cst: f64,
    /// Density at that temperature, kg/m³.
    pub oil_density_kg_m3: f64,
    /// Loss-free input power T·ω (= output power), W.
    pub input_power_w: f64,
    /// Output speed, rpm.
    pub output_speed_rpm: f64,
    /// Sum of all loss items, W (serialised as `loss_total_w` with the per-source values).
    #[serde(skip)]
    pub total_w: f64,
    /// P_out/(P_out + P_loss) with P_out the loss-free power T·ω (`physics::efficiency`);
    /// null when no power is transmitted.
    pub efficiency: Option<f64>,
    /// Totals per source and their sum, flat keys `loss_<source>_w`, `loss_total_w`.
    #[serde(flatten)]
    pub by_source: SourceValues,
    /// Every item.
    pub items: Vec<ItemReport>,
    /// What the scene left out.
    pub skipped: Vec<Skipped>,
    /// Loss models used outside their fitted range at this point, items not counted.
    pub warnings: Vec<RangeWarning>,
    /// Per bearing: friction model and μ pair with its origin.
    pub bearings: Vec<super::bearing_info::BearingInfo>,
    /// Model-form spread: every applicable model of each item's source (`losses` fills it).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub spread: Option<super::spread::SpreadBlock>,
}

/// Evaluate the scene at `op` and build the report.
pub fn losses(gb: &Gearbox, scene: &LossScene, op: &OperatingPoint, oil_temp_c: f64) -> LossReport {
    let mut out = vec![0.0; scene.len()];
    scene.evaluate(op, &mut out);
    let by = SourceValues::new(sum_by_source(&scene.items, &out), "_w", true).prefixed("loss_");
    let total: f64 = out.iter().sum();
    let p_in = op.input_torque * op.input_speed;
    // The loss items are evaluated at the loss-free torque: T·ω is the power delivered to the
    // output, and the input supplies it plus the losses.
    let efficiency = crate::physics::efficiency::efficiency(p_in, total);
    let st = &gb.gear_states[op.state];
    let rpm = 60.0 / (2.0 * std::f64::consts::PI);
    LossReport {
        model: gb.name.clone(),
        gear: st.name.clone(),
        input_speed_rpm: op.input_speed * rpm,
        input_torque_nm: op.input_torque,
        oil_temp_c,
        oil_viscosity_cst: op.oil.nu * 1e6,
        oil_density_kg_m3: op.oil.rho,
        input_power_w: p_in,
        output_speed_rpm: op.input_speed / st.ratio() * rpm,
        total_w: total,
        efficiency,
        by_source: by,
        items: scene
            .items
            .iter()
            .zip(&out)
            .map(|(it, w)| ItemReport {
                source: it.source,
                name: it.name.clone(),
                w: *w,
            })
            .collect(),
        skipped: scene.skipped.clone(),
        warnings: {
            let mut log = RangeLog::new(scene);
            log.check(scene, op);
            log.warnings(scene)
        },
        bearings: super::bearing_info::bearing_infos(gb),
        spread: None,
    }
}

/// Text table.
pub fn to_text(r: &LossReport) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "model: {}   gear {}", r.model, r.gear);
    let _ = writeln!(
        s,
        "input {:.0} rpm, {:.1} N m ({:.2} kW); output {:.0} rpm; oil {:.1} °C ({:.2} cSt, {:.1} kg/m3)\n",
        r.input_speed_rpm,
        r.input_torque_nm,
        r.input_power_w / 1e3,
        r.output_speed_rpm,
        r.oil_temp_c,
        r.oil_viscosity_cst,
        r.oil_density_kg_m3
    );
    let _ = writeln!(s, "  {:<10} {:<32} {:>12}", "source", "item", "loss [W]");
    for it in &r.items {
        let _ = writeln!(s, "  {:<10} {:<32} {:>12.3}", it.source.as_str(), it.name, it.w);
    }
    let _ = writeln!(s);
    for src in Source::ALL {
        let w = r.by_source.get(src);
        let share = if r.total_w > 0.0 {
            100.0 * w / r.total_w
        } else {
            0.0
        };
        let _ = writeln!(s, "  {:<10}{:>12.3} W  {:>5.1} %", src.as_str(), w, share);
    }
    let _ = writeln!(s, "  {:<10}{:>12.3} W", "total", r.total_w);
    let _ = writeln!(
        s,
        "  efficiency {}",
        r.efficiency
            .map_or("n/a (no power transmitted)".into(), |e| format!("{e:.5}"))
    );
    if !r.skipped.is_empty() {
        let _ = writeln!(s, "\nskipped:");
        for k in &r.skipped {
            let _ = writeln!(s, "  {}: {}", k.what, k.why);
        }
    }
    if let Some(sp) = &r.spread {
        s.push_str(&sp.to_text());
    }
    s
}
