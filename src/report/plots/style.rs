//! Shared look of every figure: canvas size, embedded font, font sizes, the fixed colour of each
//! loss source, categorical palettes, colour maps, number formatting and a legend drawer that
//! places legends in their own area (never over data).

use std::sync::OnceLock;

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use plotters::style::FontStyle;

use super::PlotError;

/// Canvas size of every PNG, pixels.
pub const WIDTH: u32 = 1600;
/// Canvas size of every PNG, pixels.
pub const HEIGHT: u32 = 1000;

/// Font family name under which the embedded DejaVu Sans is registered. It is also registered as
/// `sans-serif`, plotters' default family, so no text can fall back to a system font.
pub const FONT: &str = "sans-serif";

static DEJAVU_SANS: &[u8] = include_bytes!(concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/assets/fonts/DejaVuSans.ttf"
));
static DEJAVU_SANS_BOLD: &[u8] = include_bytes!(concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/assets/fonts/DejaVuSans-Bold.ttf"
));

/// Font size of figure titles, px at 1600×1000.
pub const TITLE_PX: u32 = 36;
/// Font size of axis descriptions, px at 1600×1000.
pub const AXIS_DESC_PX: u32 = 28;
/// Font size of tick labels, px at 1600×1000.
pub const TICK_PX: u32 = 22;
/// Font size of legend labels, px at 1600×1000.
pub const LEGEND_PX: u32 = 22;
/// Font size of notes under or beside a plot, px at 1600×1000.
pub const NOTE_PX: u32 = 19;

/// Register the embedded fonts with plotters (once per process).
pub fn ensure_fonts() -> Result<(), PlotError> {
    static DONE: OnceLock<bool> = OnceLock::new();
    let ok = *DONE.get_or_init(|| {
        let mut ok = true;
        for family in [FONT, "DejaVu Sans", "serif", "monospace"] {
            ok &= plotters::style::register_font(family, FontStyle::Normal, DEJAVU_SANS).is_ok();
            ok &= plotters::style::register_font(family, FontStyle::Bold, DEJAVU_SANS_BOLD).is_ok();
        }
        ok
    });
    if ok {
        Ok(())
    } else {
        Err(PlotError::Font)
    }
}

/// The embedded regular font at `px` pixels.
pub fn font(px: u32) -> FontDesc<'static> {
    (FONT, px).into_font()
}

/// The embedded bold font at `px` pixels.
pub fn bold(px: u32) -> FontDesc<'static> {
    (FONT, px).into_font().style(FontStyle::Bold)
}

/// Regular text at `px` pixels in the text colour.
pub fn text(px: u32) -> TextStyle<'static> {
    TextStyle::from(font(px)).color(&TEXT)
}

/// [`text`] anchored at the horizontal and vertical position `h`, `v`.
pub fn text_at(px: u32, h: HPos, v: VPos) -> TextStyle<'static> {
    text(px).pos(Pos::new(h, v))
}

/// Colour of text and axes.
pub const TEXT: RGBColor = RGBColor(25, 25, 25);
/// Colour of the minor grid lines.
pub const GRID: RGBColor = RGBColor(225, 225, 225);
/// Colour of the major grid lines and frames.
pub const GRID_BOLD: RGBColor = RGBColor(195, 195, 195);
/// Grey for outlines, hatching and items without a source colour.
pub const NEUTRAL: RGBColor = RGBColor(120, 120, 120);
/// Fill of cells without a value (map points without an equilibrium).
pub const MISSING: RGBColor = RGBColor(235, 235, 235);

/// The loss sources (the scene's list); their colour is the same in every figure.
pub use crate::scene::Source;

/// Colour of a loss source.
pub trait SourceColour {
    /// Okabe–Ito colours (colour-blind safe): blue, orange, bluish green, vermillion, reddish
    /// purple, then sky blue, yellow, black for further sources.
    fn colour(self) -> RGBColor;
}

impl SourceColour for Source {
    fn colour(self) -> RGBColor {
        match self {
            Source::Churning => RGBColor(0, 114, 178),
            Source::Pocketing => RGBColor(230, 159, 0),
            Source::Sliding => RGBColor(0, 158, 115),
            Source::Bearing => RGBColor(213, 94, 0),
            Source::Seal => RGBColor(204, 121, 167),
            Source::ClutchDrag => RGBColor(86, 180, 233),
            Source::Pump => RGBColor(240, 228, 66),
            Source::Converter => RGBColor(0, 0, 0),
        }
    }
}

/// Categorical palette for node temperatures and solvers (strong colours first).
const PALETTE: [RGBColor; 20] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(255, 127, 14),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(23, 190, 207),
    RGBColor(188, 189, 34),
    RGBColor(60, 60, 60),
    RGBColor(100, 160, 220),
    RGBColor(240, 120, 110),
    RGBColor(110, 200, 100),
    RGBColor(250, 180, 90),
    RGBColor(190, 160, 220),
    RGBColor(190, 140, 130),
    RGBColor(240, 170, 215),
    RGBColor(120, 215, 225),
    RGBColor(210, 210, 110),
    RGBColor(150, 150, 150),
];

/// Colour of the `i`-th series of a figure (the palette repeats).
pub fn series_colour(i: usize) -> RGBColor {
    PALETTE[i % PALETTE.len()]
}

/// Colour maps sampled at 0, 0.1, …, 1 (matplotlib's perceptually uniform maps).
#[derive(Clone, Copy, Debug)]
pub enum ColourMap {
    /// matplotlib's viridis (dark blue → yellow).
    Viridis,
    /// matplotlib's inferno (black → pale yellow).
    Inferno,
    /// matplotlib's plasma (dark blue → yellow through magenta).
    Plasma,
}

const VIRIDIS: [u32; 11] = [
    0x440154, 0x482475, 0x414487, 0x355f8d, 0x2a788e, 0x21918c, 0x22a884, 0x44bf70, 0x7ad151, 0xbddf26,
    0xfde725,
];
const INFERNO: [u32; 11] = [
    0x000004, 0x160b39, 0x420a68, 0x6a176e, 0x932667, 0xbc3754, 0xdd513a, 0xf37819, 0xfca50a, 0xf6d746,
    0xfcffa4,
];
const PLASMA: [u32; 11] = [
    0x0d0887, 0x41049d, 0x6a00a8, 0x8f0da4, 0xb12a90, 0xcc4778, 0xe16462, 0xf2844b, 0xfca636, 0xfcce25,
    0xf0f921,
];

impl ColourMap {
    /// Colour at `t` in [0, 1] (clamped; NaN gives the low end).
    pub fn at(self, t: f64) -> RGBColor {
        let table = match self {
            ColourMap::Viridis => &VIRIDIS,
            ColourMap::Inferno => &INFERNO,
            ColourMap::Plasma => &PLASMA,
        };
        let t = if t.is_finite() { t.clamp(0.0, 1.0) } else { 0.0 };
        let x = t * (table.len() - 1) as f64;
        let i = (x.floor() as usize).min(table.len() - 2);
        let f = x - i as f64;
        let (a, b) = (table[i], table[i + 1]);
        let ch = |c: u32, s: u32| ((c >> s) & 0xff) as f64;
        let mix = |s: u32| (ch(a, s) * (1.0 - f) + ch(b, s) * f).round() as u8;
        RGBColor(mix(16), mix(8), mix(0))
    }
}

/// A finite (lo, hi) range that contains every finite value, padded by `pad` of its width, and
/// widened when empty or degenerate (constant series, single row).
pub fn padded_range(values: impl IntoIterator<Item = f64>, pad: f64) -> (f64, f64) {
    let mut lo = f64::INFINITY;
    let mut hi = f64::NEG_INFINITY;
    for v in values {
        if v.is_finite() {
            lo = lo.min(v);
            hi = hi.max(v);
        }
    }
    pad_range(lo, hi, pad)
}

/// (lo, hi) padded by `pad` of its width; widened when empty or degenerate, (0, 1) when not
/// finite.
pub fn pad_range(lo: f64, hi: f64, pad: f64) -> (f64, f64) {
    if !lo.is_finite() || !hi.is_finite() {
        return (0.0, 1.0);
    }
    let w = hi - lo;
    if w <= f64::EPSILON * lo.abs().max(hi.abs()).max(1e-300) {
        let d = if lo.abs() > 0.0 { 0.05 * lo.abs() } else { 1.0 };
        return (lo - d, hi + d);
    }
    (lo - pad * w, hi + pad * w)
}

/// Compact tick label: plain decimals in the usual range, scientific notation outside.
pub fn fmt_num(v: f64) -> String {
    if v == 0.0 {
        return "0".into();
    }
    if !v.is_finite() {
        return "–".into();
    }
    let a = v.abs();
    if !(1e-3..1e6).contains(&a) {
        let s = format!("{v:.1e}");
        return s.replace(".0e", "e");
    }
    let decimals = if a >= 100.0 {
        0
    } else if a >= 10.0 {
        1
    } else if a >= 1.0 {
        2
    } else {
        (-(a.log10().floor()) as usize) + 2
    };
    let s = format!("{v:.decimals$}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

/// Format with thousands kept readable, for summary tables.
pub fn fmt_sig(v: f64, sig: usize) -> String {
    if !v.is_finite() {
        return "–".into();
    }
    if v == 0.0 {
        return "0".into();
    }
    let a = v.abs();
    if !(1e-3..1e7).contains(&a) {
        return format!("{:.*e}", sig.saturating_sub(1), v);
    }
    let mag = a.log10().floor() as i32;
    let decimals = (sig as i32 - 1 - mag).max(0) as usize;
    format!("{v:.decimals$}")
}

/// `v` with `decimals` decimals while that stays short (|v| < 10⁹), else with four significant
/// digits in exponent form ([`fmt_sig`]); "–" when not finite. For table cells.
pub fn fmt_fixed(v: f64, decimals: usize) -> String {
    if v.is_finite() && v.abs() < 1e9 {
        format!("{v:.decimals$}")
    } else {
        fmt_sig(v, 4)
    }
}

/// `part` as a percentage of `whole` with one decimal; "–" when `whole` is not positive or
/// the share is not a finite number.
pub fn fmt_share(part: f64, whole: f64) -> String {
    let pct = 100.0 * part / whole;
    // 100·part overflows for parts near f64::MAX; the ratio first does not.
    let pct = if pct.is_finite() {
        pct
    } else {
        100.0 * (part / whole)
    };
    if whole > 0.0 && pct.is_finite() {
        format!("{} %", fmt_fixed(pct, 1))
    } else {
        "–".into()
    }
}

/// A "nice" step (1, 2, 2.5, 5 × 10^k) giving about `n` intervals over `span`.
pub fn nice_step(span: f64, n: usize) -> f64 {
    if !(span.is_finite() && span > 0.0) {
        return 1.0;
    }
    let raw = span / n.max(1) as f64;
    let p = 10f64.powf(raw.log10().floor());
    let m = raw / p;
    let nice = if m <= 1.0 {
        1.0
    } else if m <= 2.0 {
        2.0
    } else if m <= 2.5 {
        2.5
    } else if m <= 5.0 {
        5.0
    } else {
        10.0
    };
    nice * p
}

/// Time axis: seconds up to two hours, hours beyond.
pub fn time_axis(t_max: f64) -> (f64, &'static str) {
    if t_max.abs() > 7200.0 {
        (1.0 / 3600.0, "Time (h)")
    } else {
        (1.0, "Time (s)")
    }
}

/// Marker shapes (distinct shapes so figures also read in black and white).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Marker {
    /// Filled circle.
    Circle,
    /// Filled triangle, point up.
    Triangle,
    /// Filled square.
    Square,
    /// Filled diamond.
    Diamond,
    /// Diagonal cross.
    Cross,
}

impl Marker {
    /// Marker of the `i`-th series (the five shapes repeat).
    pub fn nth(i: usize) -> Marker {
        [
            Marker::Circle,
            Marker::Triangle,
            Marker::Square,
            Marker::Diamond,
            Marker::Cross,
        ][i % 5]
    }
}

/// Draw a marker centred on pixel `(x, y)` of `area`.
pub fn draw_marker_px<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    (x, y): (i32, i32),
    m: Marker,
    r: i32,
    style: ShapeStyle,
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    match m {
        Marker::Circle => area.draw(&Circle::new((x, y), r, style)),
        Marker::Square => area.draw(&Rectangle::new([(x - r, y - r), (x + r, y + r)], style)),
        Marker::Triangle => {
            let h = (r as f64 * 1.2) as i32;
            area.draw(&Polygon::new(
                vec![(x, y - h), (x - h, y + r), (x + h, y + r)],
                style,
            ))
        }
        Marker::Diamond => {
            let h = (r as f64 * 1.3) as i32;
            area.draw(&Polygon::new(
                vec![(x, y - h), (x + h, y), (x, y + h), (x - h, y)],
                style,
            ))
        }
        Marker::Cross => {
            let s = ShapeStyle {
                filled: false,
                stroke_width: 4,
                ..style
            };
            area.draw(&PathElement::new(vec![(x - r, y - r), (x + r, y + r)], s))?;
            area.draw(&PathElement::new(vec![(x - r, y + r), (x + r, y - r)], s))
        }
    }
}

/// What a legend entry shows next to its label.
#[derive(Clone, Debug)]
pub enum Swatch {
    /// A solid line of the colour and stroke width (px).
    Line(RGBColor, u32),
    /// A dashed line of the colour and stroke width (px).
    Dashed(RGBColor, u32),
    /// A filled box of the colour.
    Fill(RGBColor),
    /// A hatched box (cells without a value).
    Hatched,
    /// A line of the colour with the marker on it.
    MarkerLine(RGBColor, Marker),
    /// A ring with a dot (a highlighted point).
    Ring(RGBColor),
}

/// One legend entry: its label and what is drawn beside it.
#[derive(Clone, Debug)]
pub struct LegendEntry {
    /// Text of the entry.
    pub label: String,
    /// What is drawn next to the text.
    pub swatch: Swatch,
}

impl LegendEntry {
    /// An entry with `label` and `swatch`.
    pub fn new(label: impl Into<String>, swatch: Swatch) -> Self {
        LegendEntry {
            label: label.into(),
            swatch,
        }
    }
}

fn draw_swatch<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    sw: &Swatch,
    x: i32,
    y: i32,
    w: i32,
    h: i32,
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    let cy = y + h / 2;
    match sw {
        Swatch::Line(c, width) => area.draw(&PathElement::new(
            vec![(x, cy), (x + w, cy)],
            c.stroke_width(*width),
        )),
        Swatch::Dashed(c, width) => {
            let style = c.stroke_width(*width);
            let mut x0 = x;
            while x0 < x + w {
                let x1 = (x0 + 10).min(x + w);
                area.draw(&PathElement::new(vec![(x0, cy), (x1, cy)], style))?;
                x0 += 16;
            }
            Ok(())
        }
        Swatch::Fill(c) => {
            area.draw(&Rectangle::new([(x, y + 2), (x + w, y + h - 2)], c.filled()))?;
            area.draw(&Rectangle::new(
                [(x, y + 2), (x + w, y + h - 2)],
                NEUTRAL.stroke_width(1),
            ))
        }
        Swatch::Hatched => {
            area.draw(&Rectangle::new(
                [(x, y + 2), (x + w, y + h - 2)],
                MISSING.filled(),
            ))?;
            hatch_px(area, (x, y + 2), (x + w, y + h - 2))?;
            area.draw(&Rectangle::new(
                [(x, y + 2), (x + w, y + h - 2)],
                NEUTRAL.stroke_width(1),
            ))
        }
        Swatch::MarkerLine(c, m) => {
            area.draw(&PathElement::new(vec![(x, cy), (x + w, cy)], c.stroke_width(3)))?;
            draw_marker_px(area, (x + w / 2, cy), *m, 8, c.filled())
        }
        Swatch::Ring(c) => {
            area.draw(&Circle::new((x + w / 2, cy), 11, c.stroke_width(4)))?;
            area.draw(&Circle::new((x + w / 2, cy), 4, c.filled()))
        }
    }
}

/// Diagonal hatching inside the pixel rectangle (x0, y0)–(x1, y1).
pub fn hatch_px<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    (x0, y0): (i32, i32),
    (x1, y1): (i32, i32),
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    let (x0, x1) = (x0.min(x1), x0.max(x1));
    let (y0, y1) = (y0.min(y1), y0.max(y1));
    let (w, h) = (x1 - x0, y1 - y0);
    if w <= 0 || h <= 0 {
        return Ok(());
    }
    let style = NEUTRAL.stroke_width(1);
    // Lines x - y = c (45°), clipped to the rectangle.
    let spacing = 9;
    let mut c = -h;
    while c < w {
        let (mut ax, mut ay) = (c, 0);
        if ax < 0 {
            ay = -ax;
            ax = 0;
        }
        let (mut bx, mut by) = (c + h, h);
        if bx > w {
            by = h - (bx - w);
            bx = w;
        }
        if ay <= h && by >= 0 && ax <= w {
            area.draw(&PathElement::new(
                vec![(x0 + ax, y0 + ay), (x0 + bx, y0 + by)],
                style,
            ))?;
        }
        c += spacing;
    }
    Ok(())
}

/// Shorten `s` so it fits in `max_px` at `px` font size.
pub fn fit_label<DB: DrawingBackend>(area: &DrawingArea<DB, Shift>, s: &str, px: u32, max_px: u32) -> String {
    let f = text(px);
    let width = |t: &str| area.estimate_text_size(t, &f).map(|(w, _)| w).unwrap_or(0);
    if width(s) <= max_px {
        return s.to_string();
    }
    let chars: Vec<char> = s.chars().collect();
    let mut n = chars.len();
    while n > 1 {
        n -= 1;
        let t: String = chars[..n].iter().collect::<String>() + "…";
        if width(&t) <= max_px {
            return t;
        }
    }
    "…".into()
}

/// Draw a vertical legend (one entry per row, several columns if needed) in `area`, which
/// should be an area of its own beside the plot. Entries that still do not fit are summarised.
pub fn draw_legend_column<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    title: Option<&str>,
    entries: &[LegendEntry],
    top: i32,
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    let (w, h) = area.dim_in_pixel();
    let (w, h) = (w as i32, h as i32);
    let mut y = top;
    if let Some(t) = title {
        area.draw(&Text::new(
            t.to_string(),
            (10, y),
            TextStyle::from(bold(LEGEND_PX)).color(&TEXT),
        ))?;
        y += (LEGEND_PX as f64 * 1.6) as i32;
    }
    if entries.is_empty() {
        return Ok(());
    }
    let avail = (h - y - 10).max(20);
    // Choose font size and number of columns so that every entry fits if at all possible.
    let mut px = LEGEND_PX;
    let mut cols = 1;
    let n = entries.len() as i32;
    loop {
        let row_h = (px as f64 * 1.45) as i32;
        let rows = (n + cols - 1) / cols;
        if rows * row_h <= avail || (px <= 14 && cols >= 3) {
            break;
        }
        if px > 16 {
            px -= 2;
        } else {
            cols += 1;
            px = (LEGEND_PX - 4).max(14);
        }
    }
    let row_h = (px as f64 * 1.45) as i32;
    let max_rows = (avail / row_h).max(1);
    let col_w = (w - 10) / cols;
    let sw_w = 40;
    let shown = (max_rows * cols).min(n) as usize;
    let truncated = shown < entries.len();
    let shown = if truncated { shown.saturating_sub(1) } else { shown };
    for (k, e) in entries.iter().take(shown).enumerate() {
        let k = k as i32;
        let rows = ((shown as i32) + cols - 1) / cols;
        let (c, r) = (k / rows, k % rows);
        let x = 10 + c * col_w;
        let yy = y + r * row_h;
        draw_swatch(area, &e.swatch, x, yy, sw_w, row_h - 4)?;
        let label = fit_label(area, &e.label, px, (col_w - sw_w - 20).max(10) as u32);
        area.draw(&Text::new(
            label,
            (x + sw_w + 8, yy + (row_h - 4) / 2),
            text_at(px, HPos::Left, VPos::Center),
        ))?;
    }
    if truncated {
        let rows = ((shown as i32) + cols - 1) / cols;
        let yy = y + rows.min(max_rows - 1).max(0) * row_h;
        let more = format!("… and {} more", entries.len() - shown);
        area.draw(&Text::new(
            more,
            (10, yy + row_h / 2),
            text_at(px, HPos::Left, VPos::Center),
        ))?;
    }
    Ok(())
}

/// Draw a one-row legend centred in `area` (a strip below or above the plot).
pub fn draw_legend_row<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    entries: &[LegendEntry],
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    let (w, h) = area.dim_in_pixel();
    let f = text(LEGEND_PX);
    let sw_w = 40;
    let widths: Vec<i32> = entries
        .iter()
        .map(|e| {
            area.estimate_text_size(&e.label, &f)
                .map(|(w, _)| w as i32)
                .unwrap_or(100)
                + sw_w
                + 40
        })
        .collect();
    let total: i32 = widths.iter().sum();
    let mut x = ((w as i32 - total) / 2).max(10);
    let row_h = (LEGEND_PX as f64 * 1.45) as i32;
    let y = (h as i32 - row_h) / 2;
    for (e, ew) in entries.iter().zip(widths) {
        draw_swatch(area, &e.swatch, x, y, sw_w, row_h)?;
        area.draw(&Text::new(
            e.label.clone(),
            (x + sw_w + 8, y + row_h / 2),
            text_at(LEGEND_PX, HPos::Left, VPos::Center),
        ))?;
        x += ew;
    }
    Ok(())
}

/// Draw the figure title (bold, centred) in a strip at the top and return the area below it.
/// (Drawn by hand rather than with `DrawingArea::titled`: with the ab_glyph backend the glyphs
/// of top-anchored text start above the anchor, which clipped the title.)
pub fn titled<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    title: &str,
) -> Result<DrawingArea<DB, Shift>, DrawingAreaErrorKind<DB::ErrorType>> {
    let (w, _) = area.dim_in_pixel();
    let style = TextStyle::from(bold(TITLE_PX))
        .color(&TEXT)
        .pos(Pos::new(HPos::Center, VPos::Center));
    let title = fit_label(area, title, TITLE_PX, w - 40);
    area.draw(&Text::new(title, (w as i32 / 2, 36), style))?;
    Ok(area.split_vertically(72).1)
}

/// A centred note (e.g. "no data") in the middle of an area.
pub fn draw_note_centre<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    s: &str,
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    let (w, h) = area.dim_in_pixel();
    area.draw(&Text::new(
        s.to_string(),
        (w as i32 / 2, h as i32 / 2),
        text_at(AXIS_DESC_PX, HPos::Center, VPos::Center),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranges_are_padded_and_finite() {
        assert_eq!(padded_range([f64::NAN], 0.05), (0.0, 1.0));
        let (lo, hi) = padded_range([3.0, 3.0], 0.05);
        assert!(lo < 3.0 && hi > 3.0);
        let (lo, hi) = padded_range([0.0], 0.05);
        assert!(lo < 0.0 && hi > 0.0);
        let (lo, hi) = padded_range([1.0, f64::NAN, 2.0], 0.1);
        assert!((lo - 0.9).abs() < 1e-12 && (hi - 2.1).abs() < 1e-12);
    }

    #[test]
    fn colour_maps_hit_their_ends() {
        let RGBColor(r, g, b) = ColourMap::Viridis.at(0.0);
        assert_eq!((r, g, b), (0x44, 0x01, 0x54));
        let RGBColor(r, g, b) = ColourMap::Viridis.at(1.0);
        assert_eq!((r, g, b), (0xfd, 0xe7, 0x25));
        let _ = ColourMap::Inferno.at(f64::NAN);
    }

    #[test]
    fn numbers_format_compactly() {
        assert_eq!(fmt_num(0.0), "0");
        assert_eq!(fmt_num(1500.0), "1500");
        assert_eq!(fmt_num(2.5), "2.5");
        assert_eq!(fmt_num(1e-6), "1e-6");
        assert_eq!(nice_step(10.0, 5), 2.0);
        assert_eq!(nice_step(0.7, 7), 0.1);
    }

    #[test]
    fn source_names_round_trip() {
        for s in Source::ALL {
            assert_eq!(Source::parse(s.as_str()), Some(s));
        }
        assert_eq!(Source::parse("windage"), None);
    }
}
