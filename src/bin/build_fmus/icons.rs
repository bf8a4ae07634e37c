//! Each FMU's `model.png` (FMI 2.0, section 2.3: the icon a tool shows), drawn here as
//! a 128 x 128 picture of the model: a wheel with a flat on a rail over sleepers
//! (TrackContact), the roll-plane vehicle's bodies on their springs (RollPlaneVehicle),
//! the half-car bogie in side view (HalfCarBogie), the vehicle on the track
//! (CoupledSystem). Encoded by the `png` crate.

const SIZE: usize = 128;

/// An RGBA picture being drawn.
struct Canvas {
    px: Vec<[u8; 4]>,
}

const STEEL: [u8; 4] = [70, 80, 95, 255];
const RAIL: [u8; 4] = [120, 120, 130, 255];
const SLEEPER: [u8; 4] = [150, 110, 70, 255];
const BODY: [u8; 4] = [40, 110, 180, 255];
const SPRING: [u8; 4] = [200, 60, 40, 255];
const FLAT: [u8; 4] = [230, 170, 30, 255];

impl Canvas {
    fn new() -> Canvas {
        Canvas {
            px: vec![[0, 0, 0, 0]; SIZE * SIZE],
        }
    }

    fn set(&mut self, x: i64, y: i64, c: [u8; 4]) {
        if (0..SIZE as i64).contains(&x) && (0..SIZE as i64).contains(&y) {
            self.px[y as usize * SIZE + x as usize] = c;
        }
    }

    fn rect(&mut self, x0: i64, y0: i64, x1: i64, y1: i64, c: [u8; 4]) {
        for y in y0..y1 {
            for x in x0..x1 {
                self.set(x, y, c);
            }
        }
    }

    /// A wheel of radius `r` at (`cx`, `cy`) with a flat at the bottom cut `depth`
    /// pixels deep (0: round), its hub drawn hollow.
    fn wheel(&mut self, cx: f64, cy: f64, r: f64, depth: f64) {
        for y in 0..SIZE as i64 {
            for x in 0..SIZE as i64 {
                let (dx, dy) = (x as f64 + 0.5 - cx, y as f64 + 0.5 - cy);
                let d = (dx * dx + dy * dy).sqrt();
                if d <= r && dy <= r - depth {
                    self.set(x, y, if d < 0.25 * r { BODY } else { STEEL });
                }
            }
        }
        if depth > 0.0 {
            // The flat, marked.
            let half = (r * r - (r - depth) * (r - depth)).sqrt();
            let y = (cy + r - depth) as i64;
            self.rect((cx - half) as i64, y - 2, (cx + half) as i64, y + 1, FLAT);
        }
    }

    /// A zigzag spring from (`x`, `y0`) down to (`x`, `y1`).
    fn spring(&mut self, x: i64, y0: i64, y1: i64) {
        for y in y0..y1 {
            let phase = (y - y0) % 8;
            let off = if phase < 4 { phase } else { 8 - phase } - 2;
            self.rect(x + 2 * off - 1, y, x + 2 * off + 2, y + 1, SPRING);
        }
    }

    fn track(&mut self, rail_y: i64) {
        for k in 0..5 {
            let x = 6 + k * 26;
            self.rect(x, rail_y + 8, x + 16, rail_y + 14, SLEEPER);
        }
        self.rect(0, rail_y, SIZE as i64, rail_y + 8, RAIL);
    }

    fn png(&self) -> Vec<u8> {
        let mut out = Vec::new();
        {
            let mut e = png::Encoder::new(&mut out, SIZE as u32, SIZE as u32);
            e.set_color(png::ColorType::Rgba);
            e.set_depth(png::BitDepth::Eight);
            let mut w = e.write_header().expect("a PNG header into memory");
            let data: Vec<u8> = self.px.iter().flatten().copied().collect();
            w.write_image_data(&data).expect("PNG data into memory");
        }
        out
    }
}

/// The `model.png` of the FMU `id`.
pub fn icon(id: &str) -> Vec<u8> {
    let mut c = Canvas::new();
    match id {
        "TrackContact" => {
            c.track(100);
            c.wheel(64.0, 58.0, 42.0, 6.0);
        }
        "Wagon" => {
            c.rect(6, 10, 122, 34, BODY);
            c.spring(28, 34, 48);
            c.spring(100, 34, 48);
            c.rect(8, 48, 50, 58, STEEL);
            c.rect(78, 48, 120, 58, STEEL);
            c.track(104);
            c.wheel(18.0, 90.0, 12.0, 3.0);
            c.wheel(40.0, 90.0, 12.0, 0.0);
            c.wheel(88.0, 90.0, 12.0, 0.0);
            c.wheel(110.0, 90.0, 12.0, 0.0);
        }
        "RollPlaneVehicle" => {
            c.rect(14, 8, 114, 30, BODY);
            c.spring(30, 30, 52);
            c.spring(98, 30, 52);
            c.rect(18, 52, 110, 62, STEEL);
            c.spring(30, 62, 80);
            c.spring(98, 62, 80);
            c.rect(20, 80, 108, 88, STEEL);
            c.wheel(26.0, 100.0, 16.0, 3.0);
            c.wheel(102.0, 100.0, 16.0, 0.0);
        }
        "HalfCarBogie" => {
            c.rect(40, 14, 88, 30, BODY);
            c.spring(64, 30, 46);
            c.rect(8, 46, 120, 58, STEEL);
            c.spring(30, 58, 70);
            c.spring(98, 58, 70);
            c.track(104);
            c.wheel(30.0, 84.0, 20.0, 4.0);
            c.wheel(98.0, 84.0, 20.0, 0.0);
        }
        _ => {
            c.rect(24, 6, 104, 26, BODY);
            c.spring(40, 26, 42);
            c.spring(88, 26, 42);
            c.rect(28, 42, 100, 50, STEEL);
            c.track(104);
            c.wheel(64.0, 76.0, 26.0, 5.0);
        }
    }
    c.png()
}
