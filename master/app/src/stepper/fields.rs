//! What a caller reads of the current state (the last committed step): the reactions of a
//! node set, the dofs of its nodes, and the Gauss-point fields, as the run directory's
//! `vtk/gauss_NNNNN.vtu` holds them ([`crate::output::pieces::gauss_state_piece`]).

use super::Stepper;
use crate::output::pieces::gauss_state_piece;
use crate::results::GaussFields;
use crate::run::{RunError, internal_length};
use cosdem_fem::assembly::{Component, Field};
use cosdem_fem::solve::{GaussPointState, SolutionView};
use std::path::Path;

impl Stepper {
    /// The reaction `[R_x, R_y, R_w]` (N, N, N m per metre of thickness) of the node set
    /// `set`: the sum of `f_int - f_ext` over its dofs at the last committed step, `[0, 0, 0]`
    /// before the first. It is the force that holds the set's prescribed dofs where they are
    /// (about zero for a set without prescribed dofs); on a symmetric job's half or quarter
    /// mesh, that of the mesh as built (times [`cosdem_job::Job::load_scale`] for the whole
    /// body). An unknown set is refused naming the known ones.
    pub fn reactions(&self, set: &str) -> Result<[f64; 3], RunError> {
        self.nodes(set)?;
        Ok(self.solver.reactions().get(set).copied().unwrap_or([0.0; 3]))
    }

    /// The value of `component` (`ux`, `uy` in m, or `w` in rad on a Cosserat mesh) at each
    /// node of the node set `set`, in the set's order (ascending node numbers:
    /// `solution().mesh.node_sets[set]`), at the last committed step. An unknown set or
    /// component is refused naming the known ones.
    pub fn displacement(&self, set: &str, component: &str) -> Result<Vec<f64>, RunError> {
        let nodes = self.nodes(set)?;
        let view = self.solver.solution();
        let known = match view.field {
            Field::Cosserat => "ux, uy, w",
            Field::Cauchy => "ux, uy",
        };
        let c = match (component, view.field) {
            ("ux", _) => Component::Ux,
            ("uy", _) => Component::Uy,
            ("w", Field::Cosserat) => Component::W,
            _ => {
                return Err(RunError::Unknown {
                    what: "component",
                    value: component.to_string(),
                    known: known.to_string(),
                });
            }
        };
        let ndf = view.field.ndf();
        Ok(nodes.iter().map(|&n| view.dofs[n * ndf + c.offset()]).collect())
    }

    /// The nodes of the node set `set`, refused naming the known sets.
    fn nodes(&self, set: &str) -> Result<&[usize], RunError> {
        let sets = &self.model.mesh.node_sets;
        sets.get(set).map(Vec::as_slice).ok_or_else(|| RunError::Unknown {
            what: "node set",
            value: set.to_string(),
            known: sets.keys().map(String::as_str).collect::<Vec<_>>().join(", "),
        })
    }

    /// The converged solution: the mesh, every dof, every Gauss point's state.
    pub fn solution(&self) -> SolutionView<'_> {
        self.solver.solution()
    }

    /// Every Gauss point's state at the last committed step (element-major): its id,
    /// position, strain `[e_xx, e_yy, e_xy, e_yx, k_x, k_y]`, stress `[s_xx, s_yy, s_xy,
    /// s_yx, m_x, m_y]` and its material's diagnostics.
    pub fn gauss_points(&self) -> &[GaussPointState] {
        self.solver.solution().gauss_points
    }

    /// The Gauss-point fields of the last committed step as [`crate::results::RunReader`]
    /// reads them from the run directory's `vtk/gauss_NNNNN.vtu` (positions, element and
    /// point ids, `strain`, `curvature`, `stress`, `couple_stress`, `equivalent_strain` with
    /// the job's internal length, and the DEM micro descriptors), whether or not a directory
    /// is written.
    pub fn gauss_fields(&self) -> Result<GaussFields, RunError> {
        let piece = gauss_state_piece(self.gauss_points(), internal_length(&self.job));
        let fields = GaussFields::from_piece(self.steps(), &piece, Path::new("(the stepper)"))?;
        Ok(fields)
    }
}
