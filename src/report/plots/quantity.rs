//! The axis of a column named by the output schema (docs/outputs.md: the unit is the name's
//! suffix): a readable description with its unit, and the multiple of the unit the values are
//! shown in (kJ or MJ for energies in J, kW for powers in W), so that no axis shows raw column
//! names or e6 ticks.

/// How a column is shown on an axis.
#[derive(Debug, Clone, PartialEq)]
pub struct AxisQuantity {
    /// Description with the unit, e.g. `energy total [MJ]`.
    pub desc: String,
    /// Values are divided by this before plotting.
    pub factor: f64,
}

/// Unit suffixes of the schema and how they are written.
const UNITS: [(&str, &str); 9] = [
    ("_j", "J"),
    ("_w", "W"),
    ("_c", "°C"),
    ("_mm", "mm"),
    ("_rpm", "rpm"),
    ("_nm", "N·m"),
    ("_s", "s"),
    ("_kmh", "km/h"),
    ("_w_per_m2k", "W/(m²·K)"),
];

/// The axis of `column` for values whose largest magnitude is `max_abs`. A parameter's key path
/// (`lubrication.oil_level_mm`) keeps its path as the description, with the unit of its last
/// key added; an output column (`energy_total_j`) is written in words (`energy total [MJ]`).
pub fn axis(column: &str, max_abs: f64) -> AxisQuantity {
    let is_path = column.contains('.') || column.contains('[');
    let (base, scale_note) = match column.strip_suffix(" (scale)") {
        Some(b) => (b, true),
        None => (column, false),
    };
    let unit = UNITS
        .iter()
        .filter(|(s, _)| base.ends_with(s))
        .max_by_key(|(s, _)| s.len())
        .map(|&(s, u)| (s, u));
    if scale_note {
        return AxisQuantity {
            desc: format!("{base} (scale)"),
            factor: 1.0,
        };
    }
    let (factor, unit_text) = match unit {
        Some((_, u)) if u == "J" || u == "W" => {
            let (f, p) = if max_abs >= 1e6 {
                (1e6, "M")
            } else if max_abs >= 1e3 {
                (1e3, "k")
            } else {
                (1.0, "")
            };
            (f, format!("{p}{u}"))
        }
        Some((_, u)) => (1.0, u.to_string()),
        None if base.contains("efficiency") => (1.0, "–".to_string()),
        None => (1.0, String::new()),
    };
    let words = if is_path {
        base.to_string()
    } else {
        let stem = unit.map_or(base, |(s, _)| &base[..base.len() - s.len()]);
        stem.replace('_', " ")
    };
    let desc = if unit_text.is_empty() {
        words
    } else {
        format!("{words} [{unit_text}]")
    };
    AxisQuantity { desc, factor }
}

#[cfg(test)]
mod tests {
    use super::axis;

    #[test]
    fn outputs_get_words_units_and_readable_multiples() {
        let a = axis("energy_total_j", 2.4e6);
        assert_eq!((a.desc.as_str(), a.factor), ("energy total [MJ]", 1e6));
        assert_eq!(axis("energy_churning_j", 4.2e4).desc, "energy churning [kJ]");
        assert_eq!(axis("loss_total_w", 900.0).desc, "loss total [W]");
        assert_eq!(axis("temp_max_sump_c", 80.0).desc, "temp max sump [°C]");
        assert_eq!(axis("cycle_efficiency", 0.9).desc, "cycle efficiency [–]");
    }

    #[test]
    fn parameters_keep_their_key_path() {
        assert_eq!(
            axis("lubrication.oil_level_mm", 80.0).desc,
            "lubrication.oil_level_mm [mm]"
        );
        assert_eq!(
            axis(r#"thermal.coolers["atf_cooler"].effectiveness"#, 0.9).desc,
            r#"thermal.coolers["atf_cooler"].effectiveness"#
        );
        let s = axis(r#"thermal.links["housing-air"].h_table.h_w_per_m2k (scale)"#, 2.0);
        assert!(s.desc.ends_with("h_w_per_m2k (scale)"), "{}", s.desc);
    }
}
