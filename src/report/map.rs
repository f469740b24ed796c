//! The outputs of an operating map, one type per file, written by `map` and read back by
//! `report DIR` with the same types: `map.csv` ([`MapRow`], one row per grid point) and
//! `map.json` ([`MapMeta`]).

use std::fmt;

use serde::de::{self, Deserialize, Deserializer, IgnoredAny, MapAccess, Visitor};

use crate::physics::units::k_to_c;
use crate::scene::{Source, N_SOURCES};
use crate::solve::sweep::MapPoint;

use super::sources::csv_columns;

/// One row of `map.csv`: a grid point and what the map found there. A point without an
/// equilibrium has every value `None` and `converged = false`. A point where a controller cycles
/// (no equilibrium exists: the limit cycle of docs/numerics.md, "Controllers that switch") has
/// the cycle's mean in the usual values and its period and oil band in `limit_cycle_period_s`,
/// `oil_min_c`, `oil_max_c` (`None` at an equilibrium).
///
/// Written by [`map_csv`] (numbers in Rust's shortest round-trip form, so a row read back is the
/// row written) and read with serde ([`Deserialize`]): a column an earlier version did not
/// write reads as `None`, the earlier names `total_loss_w` and `<source>_w` read as
/// `loss_total_w` and `loss_<source>_w`, a column this version does not know is ignored.
#[derive(Debug, Clone, PartialEq)]
pub struct MapRow {
    /// Input speed, rpm.
    pub speed_rpm: f64,
    /// Input torque, N·m.
    pub torque_nm: f64,
    /// Efficiency P_out/(P_out + P_loss) at the equilibrium, fraction (`None` without power).
    pub efficiency: Option<f64>,
    /// Total loss at the equilibrium, W (the sum of `loss_w`).
    pub loss_total_w: Option<f64>,
    /// Loss of each source at the equilibrium, W, indexed by [`Source::index`]
    /// (columns `loss_<source>_w`).
    pub loss_w: [Option<f64>; N_SOURCES],
    /// Equilibrium temperature of the oil node, °C.
    pub oil_temp_c: Option<f64>,
    /// Iterations the steady solver took (Newton and pseudo-transient together).
    pub iterations: Option<usize>,
    /// True when the steady solver converged at this point.
    pub converged: bool,
    /// Period of the controllers' limit cycle, s.
    pub limit_cycle_period_s: Option<f64>,
    /// Lowest oil temperature over the limit cycle, °C.
    pub oil_min_c: Option<f64>,
    /// Highest oil temperature over the limit cycle, °C.
    pub oil_max_c: Option<f64>,
}

impl MapRow {
    /// The row of an operating point with no result (every value empty, not converged).
    fn unsolved(speed_rpm: f64, torque_nm: f64) -> MapRow {
        MapRow {
            speed_rpm,
            torque_nm,
            efficiency: None,
            loss_total_w: None,
            loss_w: [None; N_SOURCES],
            oil_temp_c: None,
            iterations: None,
            converged: false,
            limit_cycle_period_s: None,
            oil_min_c: None,
            oil_max_c: None,
        }
    }

    /// The row of a solved grid point; `oil` is the oil node index.
    pub fn of(p: &MapPoint, oil: usize) -> MapRow {
        let mut row = MapRow::unsolved(p.speed_rpm, p.torque_nm);
        if let Some(e) = &p.equilibrium {
            row.efficiency = e.efficiency;
            row.loss_total_w = Some(e.by_source.iter().sum());
            row.loss_w = e.by_source.map(Some);
            row.oil_temp_c = Some(k_to_c(e.solution.temperatures[oil]));
            row.iterations = Some(e.solution.iterations + e.solution.ptc_iterations);
            row.converged = true;
            if let Some(c) = &e.limit_cycle {
                row.limit_cycle_period_s = Some(c.period_s);
                row.oil_min_c = Some(k_to_c(c.min_k[oil]));
                row.oil_max_c = Some(k_to_c(c.max_k[oil]));
            }
        }
        row
    }

    /// Every number of the row that is present (the reader's finiteness check).
    pub fn numbers(&self) -> impl Iterator<Item = f64> + '_ {
        let lone = [
            Some(self.speed_rpm),
            Some(self.torque_nm),
            self.efficiency,
            self.loss_total_w,
            self.oil_temp_c,
            self.limit_cycle_period_s,
            self.oil_min_c,
            self.oil_max_c,
        ];
        lone.into_iter().chain(self.loss_w).flatten()
    }

    /// The row's line of `map.csv` (without the line end).
    fn csv_line(&self) -> String {
        fn opt<T: fmt::Display>(v: Option<T>) -> String {
            v.map_or(String::new(), |x| x.to_string())
        }
        let mut fields = vec![
            self.speed_rpm.to_string(),
            self.torque_nm.to_string(),
            opt(self.efficiency),
            opt(self.loss_total_w),
        ];
        fields.extend(self.loss_w.iter().map(|v| opt(*v)));
        fields.extend([
            opt(self.oil_temp_c),
            opt(self.iterations),
            self.converged.to_string(),
            opt(self.limit_cycle_period_s),
            opt(self.oil_min_c),
            opt(self.oil_max_c),
        ]);
        fields.join(",")
    }
}

/// The header of `map.csv`.
pub fn map_header() -> String {
    format!(
        "speed_rpm,torque_nm,efficiency,loss_total_w,{},oil_temp_c,iterations,converged,\
         limit_cycle_period_s,oil_min_c,oil_max_c",
        csv_columns()
    )
}

/// `map.csv` text of `rows`.
pub fn map_csv(rows: &[MapRow]) -> String {
    let mut csv = map_header();
    csv.push('\n');
    for r in rows {
        csv.push_str(&r.csv_line());
        csv.push('\n');
    }
    csv
}

/// The source of a `loss_<source>_w` column (`<source>_w` in earlier versions).
fn source_column(key: &str) -> Option<usize> {
    let name = key.strip_suffix("_w")?;
    let name = name.strip_prefix("loss_").unwrap_or(name);
    Source::ALL.iter().find(|s| s.as_str() == name).map(|s| s.index())
}

/// An iteration count as written (an integer; earlier readers took any number).
fn count<E: de::Error>(v: Option<f64>) -> Result<Option<usize>, E> {
    match v {
        Some(x) if !(x.is_finite() && x >= 0.0 && x.fract() == 0.0) => {
            Err(E::custom(format!("iterations: {x} is not a count")))
        }
        _ => Ok(v.map(|x| x as usize)),
    }
}

struct RowVisitor;

impl<'de> Visitor<'de> for RowVisitor {
    type Value = MapRow;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("a map.csv row with named columns")
    }

    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<MapRow, A::Error> {
        let (mut speed, mut torque, mut converged) = (None, None, None);
        let mut row = MapRow::unsolved(0.0, 0.0);
        while let Some(key) = map.next_key::<String>()? {
            match key.as_str() {
                "speed_rpm" => speed = Some(map.next_value::<f64>()?),
                "torque_nm" => torque = Some(map.next_value::<f64>()?),
                "converged" => converged = Some(map.next_value::<bool>()?),
                "efficiency" => row.efficiency = map.next_value()?,
                "loss_total_w" | "total_loss_w" => row.loss_total_w = map.next_value()?,
                "oil_temp_c" => row.oil_temp_c = map.next_value()?,
                "iterations" => row.iterations = count(map.next_value::<Option<f64>>()?)?,
                "limit_cycle_period_s" => row.limit_cycle_period_s = map.next_value()?,
                "oil_min_c" => row.oil_min_c = map.next_value()?,
                "oil_max_c" => row.oil_max_c = map.next_value()?,
                k => match source_column(k) {
                    Some(i) => row.loss_w[i] = map.next_value()?,
                    None => {
                        map.next_value::<IgnoredAny>()?;
                    }
                },
            }
        }
        row.speed_rpm = speed.ok_or_else(|| de::Error::missing_field("speed_rpm"))?;
        row.torque_nm = torque.ok_or_else(|| de::Error::missing_field("torque_nm"))?;
        row.converged = converged.ok_or_else(|| de::Error::missing_field("converged"))?;
        Ok(row)
    }
}

impl<'de> Deserialize<'de> for MapRow {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<MapRow, D::Error> {
        d.deserialize_map(RowVisitor)
    }
}

/// What a map found besides its table (`map.json`); `report DIR` reads it back with this type
/// (a key an earlier version did not write reads as its default).
#[derive(Debug, Clone, Default, serde::Serialize, serde::Deserialize)]
#[serde(default)]
pub struct MapMeta {
    /// Model name.
    pub model: String,
    /// Gear-state name.
    pub gear: String,
    /// Grid points.
    pub points: usize,
    /// Points with an equilibrium (all of them in a returned map).
    pub converged: usize,
    /// Newton + pseudo-transient iterations per point.
    pub mean_iterations: f64,
    /// Wall time of the sweep, s.
    pub wall_time_s: f64,
    /// Worker threads.
    pub threads: usize,
    /// Loss models used outside their fitted range at the map's equilibria.
    pub warnings: Vec<crate::scene::RangeWarning>,
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(converged: bool) -> MapRow {
        let mut loss_w = [None; N_SOURCES];
        if converged {
            loss_w = [Some(0.1); N_SOURCES];
            loss_w[2] = Some(1e-7);
        }
        MapRow {
            speed_rpm: 1000.0 / 3.0,
            torque_nm: 12.5,
            efficiency: converged.then_some(0.987_654_321_012_345_6),
            loss_total_w: converged.then_some(123.456_789_012_345_67),
            loss_w,
            oil_temp_c: converged.then_some(80.123_456_789),
            iterations: converged.then_some(7),
            converged,
            limit_cycle_period_s: converged.then_some(61.5),
            oil_min_c: converged.then_some(79.0),
            oil_max_c: None,
        }
    }

    #[test]
    fn rows_read_back_as_written() {
        let rows = vec![row(true), row(false)];
        let text = map_csv(&rows);
        let mut rdr = csv::Reader::from_reader(text.as_bytes());
        let back: Vec<MapRow> = rdr.deserialize().collect::<Result<_, _>>().unwrap();
        assert_eq!(back, rows);
        // One field per column on every line.
        let columns = map_header().split(',').count();
        assert!(text.lines().all(|l| l.split(',').count() == columns), "{text}");
    }

    #[test]
    fn an_earlier_table_reads_with_missing_columns_as_none() {
        let text = "speed_rpm,torque_nm,efficiency,loss_total_w,loss_churning_w,oil_temp_c,iterations,converged,extra\n\
                    500,10,0.9,50,20,60.5,4,true,x\n";
        let mut rdr = csv::Reader::from_reader(text.as_bytes());
        let back: Vec<MapRow> = rdr.deserialize().collect::<Result<_, _>>().unwrap();
        assert_eq!(back[0].loss_w[Source::Churning.index()], Some(20.0));
        assert_eq!(back[0].loss_w[Source::Sliding.index()], None);
        assert_eq!(back[0].iterations, Some(4));
        assert_eq!(back[0].limit_cycle_period_s, None);
        let earlier = "speed_rpm,torque_nm,total_loss_w,sliding_w,converged\n500,10,50,5,true\n";
        let mut rdr = csv::Reader::from_reader(earlier.as_bytes());
        let back: Vec<MapRow> = rdr.deserialize().collect::<Result<_, _>>().unwrap();
        assert_eq!(back[0].loss_total_w, Some(50.0));
        assert_eq!(back[0].loss_w[Source::Sliding.index()], Some(5.0));
        let fraction = "speed_rpm,torque_nm,iterations,converged\n500,10,2.5,true\n";
        let mut rdr = csv::Reader::from_reader(fraction.as_bytes());
        assert!(rdr.deserialize::<MapRow>().next().unwrap().is_err());
        let missing = "speed_rpm,efficiency\n500,0.9\n";
        let mut rdr = csv::Reader::from_reader(missing.as_bytes());
        let err = rdr.deserialize::<MapRow>().next().unwrap().unwrap_err();
        assert!(err.to_string().contains("torque_nm"), "{err}");
    }
}
