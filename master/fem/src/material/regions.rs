//! A composite material: each Gauss point belongs to one of several materials (a material
//! per region of the mesh), and every call is routed to the owners of the points it is about.

use super::{Material, MaterialError, MaterialInput, TrialId};
use cosdem_common::micro::{AssemblyState, MicroSnapshot};
use cosdem_common::{GaussPointId, MicroResponse};
use std::collections::HashMap;
use std::fmt;

/// Why a [`Regions`] could not be built.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum RegionsError {
    /// A Gauss point is given to two parts; each point has exactly one material.
    #[error("{id} is in material part {first} and in part {second}; a point has one material")]
    Overlap {
        /// The Gauss point.
        id: GaussPointId,
        /// The first part (0-based) that lists it.
        first: usize,
        /// The second part that lists it.
        second: usize,
    },
    /// A part owns no Gauss points (an empty region: most likely a mistake in the sets).
    #[error("material part {part} owns no gauss points")]
    Empty {
        /// The part (0-based).
        part: usize,
    },
}

/// Several materials, each owning a set of Gauss points.
///
/// [`Material::evaluate`] splits the inputs by owner (keeping their order within a part),
/// evaluates every part (a part with no point in the call sees an empty slice, so that every
/// part sees every trial) and puts the answers back in the order of the inputs. Failures are
/// merged: [`MaterialError::Unavailable`] of any part wins (and ends the evaluation there);
/// otherwise the [`MaterialError::GaussPoints`] lists of all failing parts are joined, so a
/// step cut sees every failed point. A point of no part is a [`MaterialError::GaussPoints`]
/// naming it (no part is evaluated then).
pub struct Regions {
    parts: Vec<Box<dyn Material>>,
    owner: HashMap<GaussPointId, usize>,
}

impl fmt::Debug for Regions {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Regions")
            .field("parts", &self.parts.len())
            .field("points", &self.owner.len())
            .finish()
    }
}

/// The first error of calls that have all run already.
fn first_error(results: Vec<Result<(), MaterialError>>) -> Result<(), MaterialError> {
    results.into_iter().collect()
}

impl Regions {
    /// Routes each listed Gauss point to its part's material. A point listed twice in the
    /// same part is owned once; in two parts it is [`RegionsError::Overlap`]; a part with no
    /// points is [`RegionsError::Empty`].
    pub fn new(parts: Vec<(Box<dyn Material>, Vec<GaussPointId>)>) -> Result<Self, RegionsError> {
        let mut owner = HashMap::new();
        let mut materials = Vec::with_capacity(parts.len());
        for (k, (material, points)) in parts.into_iter().enumerate() {
            if points.is_empty() {
                return Err(RegionsError::Empty { part: k });
            }
            for id in points {
                match owner.insert(id, k) {
                    Some(first) if first != k => {
                        return Err(RegionsError::Overlap { id, first, second: k });
                    }
                    _ => {}
                }
            }
            materials.push(material);
        }
        Ok(Self { parts: materials, owner })
    }

    /// Number of parts.
    pub fn len(&self) -> usize {
        self.parts.len()
    }

    /// True when there are no parts.
    pub fn is_empty(&self) -> bool {
        self.parts.is_empty()
    }

    /// The part (0-based, in the order given to [`Regions::new`]) that owns a Gauss point.
    pub fn owner(&self, id: GaussPointId) -> Option<usize> {
        self.owner.get(&id).copied()
    }

    /// The part that owns `id`, or an error naming the point.
    fn owner_of(&self, id: GaussPointId) -> Result<usize, MaterialError> {
        self.owner(id)
            .ok_or_else(|| MaterialError::Unavailable(format!("{id} belongs to no material part")))
    }
}

impl Material for Regions {
    fn evaluate(
        &mut self,
        trial: TrialId,
        inputs: &[MaterialInput],
    ) -> Result<Vec<MicroResponse>, MaterialError> {
        let mut split: Vec<Vec<MaterialInput>> = vec![Vec::new(); self.parts.len()];
        let mut route = Vec::with_capacity(inputs.len());
        let mut orphans = Vec::new();
        for input in inputs {
            match self.owner.get(&input.gauss_point) {
                Some(&k) => {
                    split[k].push(*input);
                    route.push(k);
                }
                None => orphans.push((
                    input.gauss_point,
                    "belongs to no material part (no region's material covers it)".to_string(),
                )),
            }
        }
        if !orphans.is_empty() {
            return Err(MaterialError::GaussPoints(orphans));
        }
        let mut answers = Vec::with_capacity(self.parts.len());
        let mut failed = Vec::new();
        for (k, (part, part_inputs)) in self.parts.iter_mut().zip(&split).enumerate() {
            match part.evaluate(trial, part_inputs) {
                Ok(r) if r.len() == part_inputs.len() => answers.push(r.into_iter()),
                Ok(r) => {
                    return Err(MaterialError::Unavailable(format!(
                        "material part {k} answered {} of {} gauss points",
                        r.len(),
                        part_inputs.len()
                    )));
                }
                Err(MaterialError::GaussPoints(points)) => {
                    failed.extend(points);
                    answers.push(Vec::new().into_iter());
                }
                Err(e @ MaterialError::Unavailable(_)) => return Err(e),
            }
        }
        if !failed.is_empty() {
            return Err(MaterialError::GaussPoints(failed));
        }
        Ok(route
            .into_iter()
            .map(|k| answers[k].next().expect("a part answers each of its points"))
            .collect())
    }

    /// Commits every part (all of them, even after one fails), then returns the first error.
    fn commit(&mut self, step: u64) -> Result<(), MaterialError> {
        first_error(self.parts.iter_mut().map(|p| p.commit(step)).collect())
    }

    /// Rolls every part back (all of them), then returns the first error.
    fn rollback(&mut self) -> Result<(), MaterialError> {
        first_error(self.parts.iter_mut().map(|p| p.rollback()).collect())
    }

    /// Symmetric when every part is.
    fn is_symmetric(&self) -> bool {
        self.parts.iter().all(|p| p.is_symmetric())
    }

    /// `None` when no part has states; else every part's states, sorted by Gauss point.
    fn committed_states(&mut self) -> Result<Option<Vec<AssemblyState>>, MaterialError> {
        let mut all: Option<Vec<AssemblyState>> = None;
        for part in &mut self.parts {
            if let Some(states) = part.committed_states()? {
                all.get_or_insert_with(Vec::new).extend(states);
            }
        }
        if let Some(states) = &mut all {
            states.sort_by_key(|s| s.id);
        }
        Ok(all)
    }

    /// Gives each state to the part that owns its Gauss point (a state of a point no part
    /// owns is [`MaterialError::Unavailable`] naming it, before any part is touched), then
    /// restores every part that got states and returns the first error.
    fn restore_states(&mut self, states: Vec<AssemblyState>) -> Result<(), MaterialError> {
        let mut split: Vec<Vec<AssemblyState>> = self.parts.iter().map(|_| Vec::new()).collect();
        for state in states {
            let Some(k) = self.owner(state.id) else {
                return Err(MaterialError::Unavailable(format!(
                    "checkpoint state of {} belongs to no material part",
                    state.id
                )));
            };
            split[k].push(state);
        }
        first_error(
            self.parts
                .iter_mut()
                .zip(split)
                .filter(|(_, s)| !s.is_empty())
                .map(|(p, s)| p.restore_states(s))
                .collect(),
        )
    }

    /// The owner's snapshot; a point no part owns is [`MaterialError::Unavailable`].
    fn snapshot(&mut self, id: GaussPointId) -> Result<Option<MicroSnapshot>, MaterialError> {
        let k = self.owner_of(id)?;
        self.parts[k].snapshot(id)
    }
}
