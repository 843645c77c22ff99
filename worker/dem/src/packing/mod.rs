//! Reference packings: where the discs are before any macro deformation.

/// A given disc list: its overlap check (the reference state as given).
pub mod explicit;
/// Packing files in and out: YADE text and LAMMPS data files.
pub mod formats;
/// Dense hexagonal arrangement of equal discs.
pub mod hexagonal;
/// Seeded random polydisperse packing at a confining stress.
pub mod random;

/// A reference arrangement of discs (no contact histories yet).
#[derive(Clone, Debug, PartialEq)]
pub struct Packing {
    /// Centres x (m), sorted by grid cell for locality.
    pub x: Vec<f64>,
    /// Centres y (m).
    pub y: Vec<f64>,
    /// Radii (m).
    pub r: Vec<f64>,
    /// Reference region `[0, lx] x [0, ly]`: the square (penalty) or the periodic cell.
    pub lx: f64,
    /// Height of the reference region (m).
    pub ly: f64,
}

impl Packing {
    /// Reference area `V = lx ly`.
    pub fn area(&self) -> f64 {
        self.lx * self.ly
    }

    /// Sorts discs by cell (rows of `cell`-sized cells), keeping the arrangement.
    pub fn sort_by_cell(&mut self, cell: f64) {
        let nx = ((self.lx / cell).ceil() as u64).max(1);
        let key = |k: usize| -> u64 {
            let cx = ((self.x[k] / cell).floor().max(0.0) as u64).min(nx - 1);
            let cy = (self.y[k] / cell).floor().max(0.0) as u64;
            cy * nx + cx
        };
        let mut order: Vec<usize> = (0..self.x.len()).collect();
        order.sort_by_key(|&k| (key(k), k));
        self.x = order.iter().map(|&k| self.x[k]).collect();
        self.y = order.iter().map(|&k| self.y[k]).collect();
        self.r = order.iter().map(|&k| self.r[k]).collect();
    }
}
