//! A measured function of one variable: a table of points joined by straight lines,
//! read from text (two numbers a line).

use crate::error::{Error, Result, out_of_range};

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
    /// are skipped. `name` names the table in errors, with the line.
    pub fn parse(text: &str, name: &str) -> Result<Table> {
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
                        _ => return Err(Self::bad_line(name, n, k, point)),
                    },
                    _ => return Err(Self::bad_line(name, n, k, point)),
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

    /// Point `k` (from 0) of line `n` (from 0) is not two numbers.
    fn bad_line(name: &str, n: usize, k: usize, point: &str) -> Error {
        let part = if k > 0 {
            format!(", its point {} after a `;`", k + 1)
        } else {
            String::new()
        };
        Error::Table(format!(
            "{name}: line {}{part}: `{}` is not two numbers (x y, separated by blanks or a \
             comma; a `;` or a line break between points)",
            n + 1,
            point.trim().chars().take(40).collect::<String>()
        ))
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
            e.to_string().contains("rail.left.profile: line 2: `1 x`"),
            "{e}"
        );
        let e = Table::parse("0 0\n0 1\n", "rail.left.profile").unwrap_err();
        assert!(e.to_string().contains("point 2"), "{e}");
        let e = Table::parse("0 0\n", "w").unwrap_err();
        assert!(e.to_string().contains("2 to"), "{e}");
        let e = Table::parse("0 0 1\n1 1\n", "w").unwrap_err();
        assert!(e.to_string().contains("line 1"), "{e}");
        assert!(Table::parse("0 0\n1 nan\n", "w").is_err());
    }
}
