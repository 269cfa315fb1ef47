//! The parameter table's layout: columns as wide as their widest cell, free text wrapped, the
//! font shrunk until the table fits its panel, then drawn with a rule under each heading.

use super::super::style::{draw_caption, DrawResult, LEGEND_SIZE};
use super::{table_rows, Row, Tone};
use crate::material::Material;
use crate::plot_style::FONT;
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::FontStyle;

/// The table drawn into `area`: the caption, then [`layout_table`]'s pieces, a rule under each
/// heading.
pub fn draw_table<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    material: &Material,
) -> DrawResult<DB> {
    draw_caption(area, &format!("(c) {} — fitted parameters", material.name))?;
    let layout = layout_table(area, material)?;
    for piece in &layout.pieces {
        area.draw_text(&piece.text, &piece.style(), (piece.x, piece.y))?;
        if piece.kind == PieceKind::Heading {
            let rule_y = piece.y + layout.line - 3;
            area.draw(&PathElement::new(
                vec![(TABLE_LEFT, rule_y), (layout.right, rule_y)],
                RGBColor(190, 190, 190).stroke_width(1),
            ))?;
        }
    }
    Ok(())
}

/// Left margin of the table, and the gap between its columns, in pixels.
const TABLE_LEFT: i32 = 18;
const COLUMN_GAP: i32 = 18;

/// The table's first row, below the caption.
const TABLE_TOP: i32 = 50;

/// The smallest font the table shrinks to when a long table does not fit its panel.
const MIN_TABLE_SIZE: i32 = 10;

/// What a piece of the table is, which sets its font.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PieceKind {
    Heading,
    Text(Tone),
}

/// One piece of text of the table at its place (top-left corner, pixels).
#[derive(Clone, Debug, PartialEq)]
pub struct Piece {
    pub text: String,
    pub x: i32,
    pub y: i32,
    pub size: i32,
    pub kind: PieceKind,
}

impl Piece {
    fn style(&self) -> TextStyle<'static> {
        match self.kind {
            PieceKind::Heading => (FONT, self.size + 2, FontStyle::Bold)
                .into_font()
                .color(&BLACK),
            PieceKind::Text(tone) => tone_style(tone, self.size),
        }
    }
}

/// The table's pieces and its line height and right edge.
#[derive(Clone, Debug, PartialEq)]
pub struct TableLayout {
    pub pieces: Vec<Piece>,
    pub line: i32,
    pub right: i32,
}

/// Lays the table out in `area`: each column as wide as its widest cell plus a gap (fixed stops
/// let a long label or value run into its neighbour), free text wrapped to the width, and the
/// font shrunk step by step until the widest row and the last line fit the panel.
pub fn layout_table<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    material: &Material,
) -> Result<TableLayout, DrawingAreaErrorKind<DB::ErrorType>> {
    let (width, height) = area.dim_in_pixel();
    let rows = table_rows(material);
    let mut size = LEGEND_SIZE;
    loop {
        let layout = layout_at(area, &rows, size, width as i32 - 12)?;
        let fits = layout.pieces.iter().all(|piece| {
            area.estimate_text_size(&piece.text, &piece.style())
                .is_ok_and(|(w, h)| {
                    piece.x + w as i32 <= layout.right && piece.y + h as i32 <= height as i32
                })
        });
        if fits || size <= MIN_TABLE_SIZE {
            return Ok(layout);
        }
        size -= 1;
    }
}

/// [`layout_table`] at one font size, with text running up to `right`.
fn layout_at<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    rows: &[Row],
    size: i32,
    right: i32,
) -> Result<TableLayout, DrawingAreaErrorKind<DB::ErrorType>> {
    let line = size + 8;
    let stops = column_stops(area, rows, size)?;
    let mut pieces = Vec::new();
    let mut y = TABLE_TOP;
    let mut place = |text: &str, x: i32, y: i32, kind: PieceKind| {
        pieces.push(Piece {
            text: text.to_owned(),
            x,
            y,
            size,
            kind,
        })
    };
    for row in rows {
        match row {
            Row::Heading(text) => {
                y += 4;
                place(text, TABLE_LEFT, y, PieceKind::Heading);
                y += line + 2;
            }
            Row::Cells(cells, tone) => {
                for (cell, &x) in cells.iter().zip(&stops) {
                    place(cell, x, y, PieceKind::Text(*tone));
                }
                y += line;
            }
            Row::Text(text, tone) => {
                let style = tone_style(*tone, size);
                for piece in wrap(area, text, &style, (right - TABLE_LEFT) as u32)? {
                    place(&piece, TABLE_LEFT, y, PieceKind::Text(*tone));
                    y += line;
                }
            }
        }
    }
    Ok(TableLayout {
        pieces,
        line,
        right,
    })
}

/// The left edge of each column of the cell rows at font `size`: each column as wide as its
/// widest cell plus [`COLUMN_GAP`].
fn column_stops<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    rows: &[Row],
    size: i32,
) -> Result<Vec<i32>, DrawingAreaErrorKind<DB::ErrorType>> {
    let mut widths: Vec<i32> = Vec::new();
    for row in rows {
        if let Row::Cells(cells, tone) = row {
            for (i, cell) in cells.iter().enumerate() {
                let w = area.estimate_text_size(cell, &tone_style(*tone, size))?.0 as i32;
                match widths.get_mut(i) {
                    Some(widest) => *widest = (*widest).max(w),
                    None => widths.push(w),
                }
            }
        }
    }
    Ok(widths
        .iter()
        .scan(TABLE_LEFT, |x, w| {
            let stop = *x;
            *x += w + COLUMN_GAP;
            Some(stop)
        })
        .collect())
}

fn tone_style(tone: Tone, size: i32) -> TextStyle<'static> {
    let color = match tone {
        Tone::Normal => RGBColor(0, 0, 0),
        Tone::Muted => RGBColor(95, 95, 95),
        Tone::Warning => RGBColor(190, 30, 30),
    };
    (FONT, size).into_font().color(&color)
}

/// Splits `text` at spaces into lines no wider than `width` pixels.
fn wrap<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    text: &str,
    style: &TextStyle,
    width: u32,
) -> Result<Vec<String>, DrawingAreaErrorKind<DB::ErrorType>> {
    let mut lines: Vec<String> = Vec::new();
    let mut current = String::new();
    for word in text.split(' ') {
        let candidate = if current.is_empty() {
            word.to_owned()
        } else {
            format!("{current} {word}")
        };
        if !current.is_empty() && area.estimate_text_size(&candidate, style)?.0 > width {
            lines.push(std::mem::replace(&mut current, word.to_owned()));
        } else {
            current = candidate;
        }
    }
    lines.push(current);
    Ok(lines)
}

#[cfg(test)]
mod tests {
    use super::super::tests::material;
    use super::*;

    /// No text of the table overlaps another or leaves the panel, whatever the
    /// labels' lengths (fixed column stops let "cost, huber(1.5)" run into its value), and a
    /// panel too small for the full size shrinks the font instead of cutting rows off.
    #[test]
    fn table_text_never_overlaps_or_leaves_its_panel() {
        crate::plot_style::register_fonts();
        let mut m = material(24.0, 36.5);
        let fit = m.fit.as_mut().unwrap();
        fit.settings
            .insert("robust_loss".into(), "huber(1.5)".into());
        fit.uncertainty.insert("sigma".into(), 1.234e-9);
        m.name = "a_rather_long_material_name_from_a_goniometer_export".into();
        for (width, height) in [(1200, 600), (600, 560), (520, 480)] {
            let mut svg = String::new();
            let area = SVGBackend::with_string(&mut svg, (width, height)).into_drawing_area();
            let layout = layout_table(&area, &m).unwrap();
            let extent = |piece: &Piece| {
                let (w, h) = area
                    .estimate_text_size(&piece.text, &piece.style())
                    .unwrap();
                (piece.x, piece.x + w as i32, piece.y, piece.y + h as i32)
            };
            for piece in &layout.pieces {
                let (_, right, _, bottom) = extent(piece);
                assert!(
                    right <= layout.right,
                    "{width}×{height}: {piece:?} runs off"
                );
                assert!(bottom <= height as i32, "{width}×{height}: {piece:?} below");
            }
            for (i, a) in layout.pieces.iter().enumerate() {
                for b in &layout.pieces[i + 1..] {
                    let ((a0, a1, ay, _), (b0, b1, by, _)) = (extent(a), extent(b));
                    let overlap = ay == by && a0 < b1 && b0 < a1;
                    assert!(!overlap, "{width}×{height}: {a:?} overlaps {b:?}");
                }
            }
            // The report's own panel (two columns of the 3000 × 1800 figure) needs no shrinking.
            let size = layout.pieces[0].size;
            assert_eq!(
                size == LEGEND_SIZE,
                width == 1200,
                "{width}×{height}: size {size}"
            );
        }
    }
}
