//! Is the calibrated model's loss level plausible? The loss per source and the efficiency of the
//! calibrated model at the trace's highest-power rows (and at a rated point when one is given),
//! compared, for a gearbox kind with a sourced figure, with that figure.
//!
//! Sourced figures (docs/calibration.md, "Plausibility"):
//! - `wind-turbine`: "the loss in the gearbox at rated speed (on the order of 3 % of rated
//!   power)", CRC Press monograph doi:10.1201/b17936, chapter "Construction features of induction
//!   generators" (ch. 11 of the DOI's listing), text to its eq. (6.1), as shown in the
//!   publisher's abstract. An order of magnitude, not a range: the warning bounds 1.5–6 % (a
//!   factor 2 either way) are this tool's reading of "on the order of", not the source's.

use crate::model::Gearbox;
use crate::physics::units::{c_to_k, rad_s_to_rpm, rpm_to_rad_s};
use crate::report::calibration::{LossAt, Plausibility, Reference};
use crate::scene::{LossScene, OperatingPoint};

use super::problem::Problem;
use crate::job::JobError;

/// Share of the trace's rows (by power) averaged as "the highest-power rows".
pub const TOP_SHARE: f64 = 0.01;

/// A gearbox kind with a sourced loss figure.
struct Kind {
    name: &'static str,
    statement: &'static str,
    source: &'static str,
    loss_share: (f64, f64),
}

const KINDS: [Kind; 1] = [Kind {
    name: "wind-turbine",
    statement: "gearbox loss at rated speed on the order of 3 % of rated power",
    source:
        "CRC Press monograph doi:10.1201/b17936, chapter \"Construction features of induction generators\", \
             text to eq. (6.1)",
    loss_share: (0.015, 0.06),
}];

/// The kinds with a sourced figure, for messages.
pub fn kinds() -> Vec<&'static str> {
    KINDS.iter().map(|k| k.name).collect()
}

/// Check a `--gearbox-kind` value.
pub fn check_kind(kind: &str) -> Result<(), JobError> {
    if KINDS.iter().any(|k| k.name == kind) {
        return Ok(());
    }
    let allowed = kinds().join(", ");
    Err(JobError::option(
        "gearbox_kind",
        kind,
        allowed.clone(),
        format!("gearbox_kind = {kind}: no sourced loss figure for it (known: {allowed})"),
    ))
}

/// Parse a rated point `RPM:NM` (input speed, rpm, and torque, N·m): the speed in
/// (0, [`limits::SPEED_RPM`]], the torque within [`limits::TORQUE_NM`] and not 0 (negative:
/// power flowing from the output, as at a wind turbine's generator shaft), as every job's.
pub fn rated_point(s: &str) -> Result<(f64, f64), JobError> {
    use crate::job::limits::{SPEED_RPM, TORQUE_NM};
    let bad = || {
        JobError::option(
            "rated",
            s,
            format!(
                "RPM:NM, speed in (0, {}] rpm and a torque in [{}, {}] N m, not 0",
                SPEED_RPM.hi, TORQUE_NM.lo, TORQUE_NM.hi
            ),
            format!(
                "rated = {s}: must be RPM:NM (input speed in (0, {}] rpm, input torque in [{}, {}] N m, not 0)",
                SPEED_RPM.hi, TORQUE_NM.lo, TORQUE_NM.hi
            ),
        )
    };
    let (a, b) = s.split_once(':').ok_or_else(bad)?;
    let (n, t): (f64, f64) = (
        a.trim().parse().map_err(|_| bad())?,
        b.trim().parse().map_err(|_| bad())?,
    );
    let speed = n > 0.0 && n <= SPEED_RPM.hi;
    if speed && (TORQUE_NM.lo..=TORQUE_NM.hi).contains(&t) && t != 0.0 {
        Ok((n, t))
    } else {
        Err(bad())
    }
}

/// The losses of `gb` at (state, speed rad/s, torque N·m, oil °C).
fn loss_at(gb: &Gearbox, scene: &LossScene, state: usize, w: f64, t: f64, oil_c: f64) -> LossAt {
    let op = OperatingPoint {
        state,
        input_speed: w,
        input_torque: t,
        oil: gb.oil.properties(c_to_k(oil_c)),
    };
    let mut out = vec![0.0; scene.len()];
    scene.evaluate(&op, &mut out);
    let by = crate::scene::items::sum_by_source(&scene.items, &out);
    let total: f64 = out.iter().sum();
    let power = (w * t).abs();
    LossAt {
        input_speed_rpm: rad_s_to_rpm(w),
        input_torque_nm: t,
        power_w: power,
        oil_temp_c: oil_c,
        loss_by_source_w: crate::model::source::Source::ALL
            .iter()
            .filter(|s| by[s.index()] != 0.0)
            .map(|s| (s.as_str().to_string(), by[s.index()]))
            .collect(),
        loss_total_w: total,
        efficiency: (power > 0.0).then(|| power / (power + total.max(0.0))),
    }
}

/// The mean of several loss evaluations (per source, power, temperatures); efficiency of the means.
fn mean(points: &[LossAt]) -> LossAt {
    let n = points.len() as f64;
    let avg = |f: &dyn Fn(&LossAt) -> f64| points.iter().map(f).sum::<f64>() / n;
    let mut by: Vec<(String, f64)> = Vec::new();
    for p in points {
        for (s, v) in &p.loss_by_source_w {
            match by.iter_mut().find(|(x, _)| x == s) {
                Some(e) => e.1 += v / n,
                None => by.push((s.clone(), v / n)),
            }
        }
    }
    let (power, total) = (avg(&|p| p.power_w), avg(&|p| p.loss_total_w));
    LossAt {
        input_speed_rpm: avg(&|p| p.input_speed_rpm),
        input_torque_nm: avg(&|p| p.input_torque_nm),
        power_w: power,
        oil_temp_c: avg(&|p| p.oil_temp_c),
        loss_by_source_w: by,
        loss_total_w: total,
        efficiency: (power > 0.0).then(|| power / (power + total.max(0.0))),
    }
}

/// The plausibility report of the calibrated model at θ over the rows of `parts` (each a
/// problem, one segment of one trace, with its simulated temperatures, °C, `[row][channel]`;
/// every part holds the same parameters, θ); None for a vehicle trace or a trace that does not
/// measure the oil node (noted in `warnings`). A loss share outside the kind's sourced bounds is
/// warned.
pub fn assess(
    parts: &[(&Problem<'_>, &[Vec<f64>])],
    theta: &[f64],
    kind: Option<&str>,
    rated: Option<(f64, f64)>,
    warnings: &mut Vec<String>,
) -> Result<Option<Plausibility>, JobError> {
    let Some(&(pr, _)) = parts.first() else {
        return Ok(None);
    };
    let gb = pr.gearbox_at(theta)?;
    let Some(net) = gb.thermal.as_ref() else {
        return Ok(None);
    };
    let oil: Option<Vec<usize>> = parts
        .iter()
        .map(|(p, _)| p.channels.iter().position(|&n| n == net.oil_node))
        .collect();
    let Some(oil) = oil else {
        warnings.push("plausibility: the trace does not measure the oil node: losses not evaluated".into());
        return Ok(None);
    };
    let rig = |p: &Problem<'_>, t: &[Vec<f64>]| {
        p.trace.cycle.kind == crate::cycle::CycleKind::Rig && p.trace.cycle.rows.len() == t.len()
    };
    if !parts.iter().all(|&(p, t)| rig(p, t)) {
        return Ok(None);
    }
    let scene =
        LossScene::compile(&gb).map_err(|e| JobError::invalid(format!("{}: {e}", pr.file.display())))?;
    let state_of = |g: &Option<String>| g.as_deref().and_then(|g| gb.state_index(g)).unwrap_or(0);
    let mut order: Vec<(usize, usize)> = parts
        .iter()
        .enumerate()
        .flat_map(|(k, (p, _))| (0..p.trace.cycle.rows.len()).map(move |r| (k, r)))
        .collect();
    let row = |(k, r): (usize, usize)| &parts[k].0.trace.cycle.rows[r];
    let power = |x: (usize, usize)| (row(x).input_speed * row(x).input_torque).abs();
    order.sort_by(|&a, &b| power(b).total_cmp(&power(a)));
    let top = ((order.len() as f64 * TOP_SHARE).ceil() as usize).clamp(1, order.len());
    let points: Vec<LossAt> = order[..top]
        .iter()
        .map(|&(k, r)| {
            let x = row((k, r));
            loss_at(
                &gb,
                &scene,
                state_of(&x.gear),
                x.input_speed,
                x.input_torque,
                parts[k].1[r][oil[k]],
            )
        })
        .collect();
    let highest = mean(&points);
    let rated_at = rated.map(|(n, t)| {
        let w = rpm_to_rad_s(n);
        loss_at(
            &gb,
            &scene,
            state_of(&row(order[0]).gear),
            w,
            t,
            highest.oil_temp_c,
        )
    });
    let reference = kind.and_then(|k| KINDS.iter().find(|x| x.name == k)).map(|k| {
        let at = rated_at.as_ref().unwrap_or(&highest);
        let share = at.loss_total_w / at.power_w.max(f64::MIN_POSITIVE);
        let inside = (k.loss_share.0..=k.loss_share.1).contains(&share);
        if !inside {
            warnings.push(format!(
                "plausibility: the calibrated model loses {:.1} % of {:.0} kW at {} ({:.0} rpm, {:.0} N m, oil \
                 {:.1} °C): outside {:.1}–{:.1} %, the bounds this tool reads from the sourced figure for a {} \
                 gearbox ({}; {}); the loss level is what the fit traded against the cooler",
                100.0 * share,
                at.power_w / 1e3,
                if rated_at.is_some() { "the rated point" } else { "the highest-power rows" },
                at.input_speed_rpm,
                at.input_torque_nm,
                at.oil_temp_c,
                100.0 * k.loss_share.0,
                100.0 * k.loss_share.1,
                k.name,
                k.statement,
                k.source
            ));
        }
        Reference {
            kind: k.name,
            statement: k.statement,
            source: k.source,
            loss_share_bounds: k.loss_share,
            loss_share: share,
            inside,
        }
    });
    Ok(Some(Plausibility {
        rows: top,
        highest_power: highest,
        rated: rated_at,
        reference,
    }))
}
