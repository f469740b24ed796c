//! The axes of one chart panel: grid lines, tick counts and labels, axis descriptions and their
//! fonts. Every figure configures plotters' mesh through [`Axes::draw`]; [`Axes::house`] is the
//! common look (the style's tick and description fonts, light and bold grid lines), and what a
//! panel does not set stays at plotters' default.

use plotters::coord::ranged1d::{Ranged, ValueFormatter};
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;

use super::style;
use super::DrawResult;

/// A chart with f64 axes on a figure's canvas.
pub type Chart<'b> = ChartContext<'b, BitMapBackend<'b>, Cartesian2d<RangedCoordf64, RangedCoordf64>>;

/// The grid lines of a panel.
#[derive(Debug, Clone, Copy)]
pub enum Grid {
    /// Light and bold lines in both directions, in these colours (`None`: plotters' default).
    Lines {
        /// Colour of the minor (light) lines.
        light: Option<RGBColor>,
        /// Colour of the major (bold) lines.
        bold: Option<RGBColor>,
    },
    /// Only the lines across the x axis, in the house colours (bars, one row per category).
    Vertical,
    /// No grid lines (heat maps).
    Off,
}

impl Grid {
    /// The house grid: light lines in [`style::GRID`], bold ones in [`style::GRID_BOLD`].
    pub const HOUSE: Grid = Grid::Lines {
        light: Some(style::GRID),
        bold: Some(style::GRID_BOLD),
    };
}

/// Tick-label formatter of an axis whose values are `V`.
pub type Format<'f, V> = &'f dyn Fn(&V) -> String;

/// The axes of one panel, built from [`Axes::house`] or [`Axes::with_fonts`] and drawn once with
/// [`Axes::draw`]. `XV`, `YV`: the value types of the x and y coordinates.
pub struct Axes<'f, XV = f64, YV = f64> {
    x_desc: Option<String>,
    y_desc: Option<String>,
    x_labels: Option<usize>,
    y_labels: Option<usize>,
    x_format: Option<Format<'f, XV>>,
    y_format: Option<Format<'f, YV>>,
    x_tick_style: TextStyle<'static>,
    y_tick_style: TextStyle<'static>,
    desc_style: TextStyle<'static>,
    grid: Grid,
    x_axis: bool,
}

impl<'f, XV, YV> Axes<'f, XV, YV> {
    /// The house look: ticks at [`style::TICK_PX`], descriptions at [`style::AXIS_DESC_PX`], the
    /// house grid.
    pub fn house() -> Self {
        Self::with_fonts(
            style::font(style::TICK_PX).into(),
            style::font(style::AXIS_DESC_PX).into(),
        )
        .grid(Grid::HOUSE)
    }

    /// Tick labels in `tick`, descriptions in `desc`, plotters' default grid.
    pub fn with_fonts(tick: TextStyle<'static>, desc: TextStyle<'static>) -> Self {
        Axes {
            x_desc: None,
            y_desc: None,
            x_labels: None,
            y_labels: None,
            x_format: None,
            y_format: None,
            x_tick_style: tick.clone(),
            y_tick_style: tick,
            desc_style: desc,
            grid: Grid::Lines {
                light: None,
                bold: None,
            },
            x_axis: true,
        }
    }

    /// Description of the x axis.
    pub fn x_desc(mut self, desc: impl Into<String>) -> Self {
        self.x_desc = Some(desc.into());
        self
    }

    /// Description of the y axis.
    pub fn y_desc(mut self, desc: impl Into<String>) -> Self {
        self.y_desc = Some(desc.into());
        self
    }

    /// Tick counts (plotters' "at most this many labels") of the x and y axes.
    pub fn labels(self, x: usize, y: usize) -> Self {
        self.x_labels(x).y_labels(y)
    }

    /// Tick count of the x axis.
    pub fn x_labels(mut self, n: usize) -> Self {
        self.x_labels = Some(n);
        self
    }

    /// Tick count of the y axis.
    pub fn y_labels(mut self, n: usize) -> Self {
        self.y_labels = Some(n);
        self
    }

    /// Tick labels of the x axis.
    pub fn x_format(mut self, f: Format<'f, XV>) -> Self {
        self.x_format = Some(f);
        self
    }

    /// Tick labels of the y axis.
    pub fn y_format(mut self, f: Format<'f, YV>) -> Self {
        self.y_format = Some(f);
        self
    }

    /// Font of the y tick labels (e.g. category names that shrink with their number).
    pub fn y_tick_style(mut self, style: TextStyle<'static>) -> Self {
        self.y_tick_style = style;
        self
    }

    /// Grid lines.
    pub fn grid(mut self, grid: Grid) -> Self {
        self.grid = grid;
        self
    }

    /// No x axis (a colour bar).
    pub fn without_x_axis(mut self) -> Self {
        self.x_axis = false;
        self
    }

    /// Draw the axes and grid of `chart`.
    pub fn draw<'a, X, Y>(
        &self,
        chart: &mut ChartContext<'a, BitMapBackend<'a>, Cartesian2d<X, Y>>,
    ) -> DrawResult
    where
        X: Ranged<ValueType = XV> + ValueFormatter<XV>,
        Y: Ranged<ValueType = YV> + ValueFormatter<YV>,
    {
        let mut mesh = chart.configure_mesh();
        mesh.x_label_style(self.x_tick_style.clone())
            .y_label_style(self.y_tick_style.clone())
            .axis_desc_style(self.desc_style.clone());
        if let Some(d) = &self.x_desc {
            mesh.x_desc(d.as_str());
        }
        if let Some(d) = &self.y_desc {
            mesh.y_desc(d.as_str());
        }
        if let Some(n) = self.x_labels {
            mesh.x_labels(n);
        }
        if let Some(n) = self.y_labels {
            mesh.y_labels(n);
        }
        if let Some(f) = self.x_format {
            mesh.x_label_formatter(f);
        }
        if let Some(f) = self.y_format {
            mesh.y_label_formatter(f);
        }
        match self.grid {
            Grid::Lines { light, bold } => {
                if let Some(c) = light {
                    mesh.light_line_style(c);
                }
                if let Some(c) = bold {
                    mesh.bold_line_style(c);
                }
            }
            Grid::Vertical => {
                mesh.disable_y_mesh()
                    .light_line_style(style::GRID)
                    .bold_line_style(style::GRID_BOLD);
            }
            Grid::Off => {
                mesh.disable_mesh();
            }
        }
        if !self.x_axis {
            mesh.disable_x_axis();
        }
        mesh.draw()?;
        Ok(())
    }
}

/// Compact tick labels ([`style::fmt_num`]) for an f64 axis.
pub fn compact(v: &f64) -> String {
    style::fmt_num(*v)
}

/// No tick labels (an axis another panel labels).
pub fn blank(_: &f64) -> String {
    String::new()
}

/// The time axis of a run figure over the rows `order` (in time order): the display scale (s or
/// h, [`style::time_axis`]), its description and the axis range.
#[derive(Debug, Clone, Copy)]
pub struct TimeAxis {
    /// Display units per second.
    pub scale: f64,
    /// Axis description.
    pub desc: &'static str,
    /// Axis range in display units.
    pub x0: f64,
    /// Axis range in display units.
    pub x1: f64,
}

impl TimeAxis {
    /// The axis over the times `time_s` of the rows `order`.
    pub fn over(time_s: &[f64], order: &[usize]) -> TimeAxis {
        let t_lo = order.first().map(|&i| time_s[i]).unwrap_or(0.0);
        let t_hi = order.last().map(|&i| time_s[i]).unwrap_or(1.0);
        let (scale, desc) = style::time_axis(t_hi);
        let (x0, x1) = if t_hi > t_lo {
            (t_lo * scale, t_hi * scale)
        } else {
            style::pad_range(t_lo * scale, t_hi * scale, 0.0)
        };
        TimeAxis { scale, desc, x0, x1 }
    }
}
