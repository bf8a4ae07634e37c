//! A measured function of one variable: a table of points joined by straight lines,
//! read from text (two numbers a line).

use crate::error::{Error, Result, num, out_of_range};

/// Points `(x_i, y_i)` with strictly increasing `x`, at least two, every value finite;
/// between points the straight line, beyond the ends the end values.
#[derive(Debug, Clone, PartialEq)]
pub struct Table {
    x: Vec<f64>,
    y: Vec<f64>,
}

/// Points a table may hold (a measured profile of 100 km every 0.1 m).
pub const MAX_TABLE_POINTS: usize = 1_000_000;

impl Table {
    /// The table of `x`, `y` (equal lengths, 2 to [`MAX_TABLE_POINTS`] points, `x`
    /// strictly increasing, all finite). `name` names the table in errors.
    pub fn new(x: Vec<f64>, y: Vec<f64>, name: &str) -> Result<Table> {
        if x.len() != y.len() || !(2..=MAX_TABLE_POINTS).contains(&x.len()) {
            return Err(out_of_range(
                name,
                x.len().min(y.len()) as f64,
                format!("2 to {MAX_TABLE_POINTS} points, two numbers each"),
            ));
        }
        for (i, (&a, &b)) in x.iter().zip(&y).enumerate() {
            if !(a.is_finite() && b.is_finite()) {
                return Err(out_of_range(
                    &format!("{name}, point {}", i + 1),
                    if a.is_finite() { b } else { a },
                    "finite numbers",
                ));
            }
            if i > 0 && a <= x[i - 1] {
                return Err(out_of_range(
                    &format!("{name}, point {}", i + 1),
                    a,
                    format!(
                        "above the point before's {} (strictly increasing)",
                        x[i - 1]
                    ),
                ));
            }
        }
        Ok(Table { x, y })
    }

    /// Reads a table from text: one point a line, two numbers separated by blanks or a
    /// comma; a `;` also ends a point, so that a whole table fits on one line
    /// (`0 0; 0.1 1e-5; 0.2 0`, or `0,0;0.1,1e-5;0.2,0` without blanks). Empty lines and text after `#`
    /// are skipped; a UTF-8 byte-order mark before the first point is too. `name` names
    /// the table in errors, with the line and the point; no error quotes the text, which
    /// may be any file's.
    pub fn parse(text: &str, name: &str) -> Result<Table> {
        let text = text.strip_prefix('\u{feff}').unwrap_or(text);
        if !text.contains('\n') && text.contains('#') {
            return Err(Error::Table(format!(
                "{name}: a `#` in a table on one line would make the rest of the line, \
                 points and all, a comment: take the comment out, or give the table a \
                 line a point"
            )));
        }
        let (mut x, mut y) = (Vec::new(), Vec::new());
        for (n, line) in text.lines().enumerate() {
            let line = line.split('#').next().unwrap_or("");
            for (k, point) in line.split(';').enumerate() {
                let fields: Vec<&str> = point
                    .split(|c: char| c.is_whitespace() || c == ',')
                    .filter(|f| !f.is_empty())
                    .collect();
                match fields.as_slice() {
                    [] => {}
                    [a, b] => match (a.parse::<f64>(), b.parse::<f64>()) {
                        (Ok(a), Ok(b)) => {
                            x.push(a);
                            y.push(b);
                        }
                        _ => return Err(Self::bad_line(name, n, k, None)),
                    },
                    f => return Err(Self::bad_line(name, n, k, Some(f.len()))),
                }
                if x.len() > MAX_TABLE_POINTS {
                    return Err(out_of_range(
                        name,
                        x.len() as f64,
                        format!("at most {MAX_TABLE_POINTS} points"),
                    ));
                }
            }
        }
        Table::new(x, y, name)
    }

    /// Point `k` (from 0) of line `n` (from 0) is not two numbers: it has `fields`
    /// fields, or two that are not both numbers. The text itself is not quoted.
    fn bad_line(name: &str, n: usize, k: usize, fields: Option<usize>) -> Error {
        let part = if k > 0 {
            format!(", its point {} after a `;`", k + 1)
        } else {
            String::new()
        };
        let what = match fields {
            Some(f) => format!("{f} fields where a point has 2"),
            None => "2 fields that are not both numbers".into(),
        };
        Error::Table(format!(
            "{name}: line {}{part}: {what} (x y, separated by blanks or a comma; a `;` or a \
             line break between points)",
            n + 1,
        ))
    }

    /// Checks that a wheel can follow the table as a contact does, judged by its
    /// straight pieces: no piece rises or falls more steeply than `max_slope` (units of
    /// `y` per metre), and at no point does the slope change by more than
    /// `max_curvature` (1/m) times the shorter of the two pieces that meet there, nor by
    /// more than `max_curvature` times `corner` (m). A sampled curve turns at each point
    /// by its curvature times the spacing; a corner between long pieces is a turn at a
    /// point all the same, which the contact, reading the table at the wheel's point,
    /// meets as a jump of the wheel's vertical velocity: it is held to what the
    /// reference curve turns at a point when sampled every `corner`. Beyond the ends the
    /// table holds its end values, so an end counts as a point where its piece meets a
    /// slope of 0, or the piece to the first point a period on when the table repeats
    /// every `period` of `x`. `metres_per_x` converts `x` to metres (1 for positions,
    /// the wheel radius for angles). `limit` says where the limits come from.
    ///
    /// Errors: the first piece or point beyond a limit, naming the table, the point (from
    /// 1), the value and the limit.
    pub fn check_followable(
        &self,
        name: &str,
        metres_per_x: f64,
        period: Option<f64>,
        (max_slope, max_curvature, corner): (f64, f64, f64),
        limit: &str,
    ) -> Result<()> {
        let (x, y) = (&self.x, &self.y);
        let n = x.len();
        // Piece i runs from point i to point i + 1; with a period, piece n - 1 wraps.
        let pieces = if period.is_some() { n } else { n - 1 };
        let piece = |i: usize| -> (f64, f64) {
            let (x1, y1) = match (i + 1 < n, period) {
                (true, _) => (x[i + 1], y[i + 1]),
                (false, Some(p)) => (x[0] + p, y[0]),
                (false, None) => unreachable!("a piece past the last point"),
            };
            let len = (x1 - x[i]) * metres_per_x;
            ((y1 - y[i]) / len, len)
        };
        for i in 0..pieces {
            let (s, _) = piece(i);
            if s.abs() > max_slope {
                let j = (i + 1) % n;
                return Err(out_of_range(
                    &format!(
                        "{name}, points {} to {} (x = {} to {})",
                        i + 1,
                        j + 1,
                        num(x[i]),
                        num(x[j])
                    ),
                    s,
                    format!("a slope of at most {max_slope:.4} either way ({limit})"),
                ));
            }
        }
        for i in 0..n {
            let before = match (i, period) {
                (0, None) => (0.0, f64::INFINITY),
                (0, Some(_)) => piece(n - 1),
                _ => piece(i - 1),
            };
            let after = if i < pieces {
                piece(i)
            } else {
                (0.0, f64::INFINITY)
            };
            let turn = (after.0 - before.0).abs();
            let over = before.1.min(after.1).min(corner);
            if turn > max_curvature * over {
                return Err(out_of_range(
                    &format!(
                        "{name}, point {} (change of slope at x = {})",
                        i + 1,
                        num(x[i])
                    ),
                    turn,
                    format!(
                        "at most {max_curvature:.3} 1/m times the shorter piece there, and at \
                         most {:.4} at any point ({max_curvature:.3} 1/m over {corner} m), \
                         here {:.4} ({limit})",
                        max_curvature * corner,
                        max_curvature * over
                    ),
                ));
            }
        }
        Ok(())
    }

    /// The first and last `x`.
    pub fn range(&self) -> (f64, f64) {
        (self.x[0], self.x[self.x.len() - 1])
    }

    /// The points.
    pub fn points(&self) -> (&[f64], &[f64]) {
        (&self.x, &self.y)
    }

    /// The segment `i` (`x_i <= x < x_(i+1)`) that holds `x`, clamped to the first and
    /// last.
    #[inline]
    fn segment(&self, x: f64) -> usize {
        let n = self.x.len();
        self.x.partition_point(|&a| a <= x).clamp(1, n - 1) - 1
    }

    /// The value at `x`: the straight line between the points around it, the end
    /// values beyond the ends.
    #[inline]
    pub fn at(&self, x: f64) -> f64 {
        let (first, last) = self.range();
        if x <= first {
            return self.y[0];
        }
        if x >= last {
            return self.y[self.y.len() - 1];
        }
        let i = self.segment(x);
        let w = (x - self.x[i]) / (self.x[i + 1] - self.x[i]);
        self.y[i] + w * (self.y[i + 1] - self.y[i])
    }

    /// The slope `dy/dx` at `x`: the segment's; 0 beyond the ends.
    #[inline]
    pub fn slope_at(&self, x: f64) -> f64 {
        let (first, last) = self.range();
        if x < first || x > last {
            return 0.0;
        }
        let i = self.segment(x);
        (self.y[i + 1] - self.y[i]) / (self.x[i + 1] - self.x[i])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_table_reads_lines_or_one_line_and_joins_its_points_by_straight_lines() {
        let t = Table::parse("# x y\n0 0\n1, 2\n\n3 4  # end\n", "t").unwrap();
        assert_eq!(t, Table::parse("0 0; 1 2; 3 4", "t").unwrap());
        assert_eq!(t.at(0.5), 1.0);
        assert_eq!(t.at(2.0), 3.0);
        assert_eq!(t.at(-1.0), 0.0);
        assert_eq!(t.at(9.0), 4.0);
        assert_eq!(t.slope_at(0.5), 2.0);
        assert_eq!(t.slope_at(2.5), 1.0);
        assert_eq!(t.slope_at(9.0), 0.0);
        assert_eq!(t.at(1.0), 2.0);
    }

    #[test]
    fn a_bad_table_is_refused_with_its_name_and_line() {
        let e = Table::parse("0 0\n1 x\n", "rail.left.profile").unwrap_err();
        assert!(
            e.to_string()
                .contains("rail.left.profile: line 2: 2 fields that are not both numbers"),
            "{e}"
        );
        let e = Table::parse("0 0\n0 1\n", "rail.left.profile").unwrap_err();
        assert!(e.to_string().contains("point 2"), "{e}");
        let e = Table::parse("0 0\n", "w").unwrap_err();
        assert!(e.to_string().contains("2 to"), "{e}");
        let e = Table::parse("0 0 1\n1 1\n", "w").unwrap_err();
        assert!(e.to_string().contains("line 1: 3 fields"), "{e}");
        assert!(Table::parse("0 0\n1 nan\n", "w").is_err());
    }

    #[test]
    fn a_refused_table_is_never_quoted_and_a_byte_order_mark_is_skipped() {
        let e = Table::parse("PATH=/secret/value\nHOME=/root\n", "rail.left.profile");
        let e = e.unwrap_err().to_string();
        assert!(e.contains("line 1") && e.contains("1 fields"), "{e}");
        assert!(!e.contains("secret") && !e.contains("PATH"), "{e}");
        let e = Table::parse("0 0\nkey value\n", "t")
            .unwrap_err()
            .to_string();
        assert!(e.contains("line 2") && !e.contains("key"), "{e}");
        assert_eq!(
            Table::parse("\u{feff}0 0\n1 2\n", "t").unwrap(),
            Table::parse("0 0; 1 2", "t").unwrap()
        );
    }

    #[test]
    fn a_table_steeper_or_sharper_than_the_limits_is_refused_at_its_point() {
        let limits = (0.5, 15.0, 1.0);
        // A ramp of slope 0.25 over 1 m each side of a plateau: turns of 0.25 in 1 m.
        let ok = Table::parse("0 0; 1 0.25; 2 0.25; 3 0", "t").unwrap();
        ok.check_followable("t", 1.0, None, limits, "test").unwrap();
        // Slope 0.6 > 0.5 on the second piece.
        let steep = Table::parse("0 0; 1 0; 2 0.6", "t").unwrap();
        let e = steep
            .check_followable("t", 1.0, None, limits, "test")
            .unwrap_err();
        let e = e.to_string();
        assert!(
            e.contains("points 2 to 3 (x = 1 to 2)") && e.contains("0.6"),
            "{e}"
        );
        // The same table in centimetres of x is 100 times steeper.
        assert!(
            ok.check_followable("t", 0.01, None, limits, "test")
                .is_err()
        );
        // A spike of slopes +-0.1 over 0.01 m each: a turn of 0.1 at its foot, point 2
        // (10 1/m against the shorter piece), 0.2 at its top, point 3 (20 1/m).
        let kink = Table::parse("0 0; 0.99 0; 1 0.001; 1.01 0; 2 0", "t").unwrap();
        let e = kink
            .check_followable("t", 1.0, None, limits, "test")
            .unwrap_err();
        let e = e.to_string();
        assert!(e.contains("point 3 (change of slope at x = 1)"), "{e}");
        assert!(e.contains("at most 15.000 1/m"), "{e}");
        let lower = Table::parse("0 0; 0.99 0; 1 0.0007; 1.01 0; 2 0", "t").unwrap();
        lower
            .check_followable("t", 1.0, None, limits, "test")
            .unwrap();
        // An end counts against the held end value: a table starting on slope 0.4 over
        // 0.01 m turns by 0.4 over 0.005 m at point 1.
        let end = Table::parse("0 0; 0.01 0.004; 1 0.004", "t").unwrap();
        let e = end
            .check_followable("t", 1.0, None, limits, "test")
            .unwrap_err();
        assert!(e.to_string().contains("point 1 (change"), "{e}");
        // With a period the last point joins the first: a step there is a piece.
        let wrap = Table::parse("0 0; 1 0; 2 0", "t").unwrap();
        wrap.check_followable("t", 1.0, Some(3.0), limits, "test")
            .unwrap();
        let wrap = Table::parse("0 0; 1 0; 2 0.3", "t").unwrap();
        let e = wrap
            .check_followable("t", 1.0, Some(2.5), limits, "test")
            .unwrap_err();
        assert!(e.to_string().contains("points 3 to 1"), "{e}");
        // A corner between long pieces: a turn of 0.4 at point 2 passes against 15 1/m
        // times 1 m pieces, not against 15 1/m over a corner length of 0.02 m (0.3).
        let corner = Table::parse("0 0; 1 0; 2 0.4; 3 0.4", "t").unwrap();
        corner
            .check_followable("t", 1.0, None, limits, "test")
            .unwrap();
        let e = corner
            .check_followable("t", 1.0, None, (0.5, 15.0, 0.02), "test")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("point 2 (change of slope at x = 1)") && e.contains("here 0.3000"),
            "{e}"
        );
    }
}
