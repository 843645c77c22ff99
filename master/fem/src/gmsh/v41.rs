//! MSH 4.1 ASCII: `$Entities` (which carry the physical groups) and the block-structured
//! `$Nodes` and `$Elements`.

use super::Result;
use super::ascii::Cursor;
use super::records::{CAPACITY_HINT, ElemRec, NodeRec, check_planar};
use std::collections::HashMap;

/// 4.1 `$Entities`: (dimension, entity tag) -> physical tags.
pub(super) fn parse_entities(cur: &mut Cursor<'_>) -> Result<HashMap<(u32, i32), Vec<i32>>> {
    let mut f = cur.fields("the entity counts")?;
    let counts = [
        f.count("the number of points")?,
        f.count("the number of curves")?,
        f.count("the number of surfaces")?,
        f.count("the number of volumes")?,
    ];
    f.finish()?;
    let mut out = HashMap::new();
    for (dim, &n) in counts.iter().enumerate() {
        for _ in 0..n {
            let mut f = cur.fields("an entity")?;
            let tag: i32 = f.next("an entity tag")?;
            let n_coords = if dim == 0 { 3 } else { 6 };
            for _ in 0..n_coords {
                f.next::<f64>("an entity coordinate")?;
            }
            let n_phys = f.count("the number of physical tags")?;
            let mut phys = Vec::with_capacity(n_phys.min(CAPACITY_HINT));
            for _ in 0..n_phys {
                phys.push(f.next::<i32>("a physical tag")?);
            }
            if dim > 0 {
                let n_bound = f.count("the number of bounding entities")?;
                for _ in 0..n_bound {
                    f.next::<i32>("a bounding entity tag")?;
                }
            }
            f.finish()?;
            out.insert((dim as u32, tag), phys);
        }
    }
    Ok(out)
}

/// 4.1 `$Nodes`: entity blocks of node tags followed by their coordinates.
pub(super) fn parse_nodes(cur: &mut Cursor<'_>) -> Result<Vec<(NodeRec, usize)>> {
    let mut f = cur.fields("the node block header")?;
    let n_blocks = f.count("the number of node blocks")?;
    let n_nodes = f.count("the number of nodes")?;
    f.next::<u64>("the minimum node tag")?;
    f.next::<u64>("the maximum node tag")?;
    f.finish()?;
    let header_line = f.line;
    let mut out = Vec::with_capacity(n_nodes.min(CAPACITY_HINT));
    for _ in 0..n_blocks {
        let mut f = cur.fields("a node block `dim tag parametric count`")?;
        let _dim: u32 = f.next("an entity dimension")?;
        let _tag: i32 = f.next("an entity tag")?;
        let parametric: u32 = f.next("the parametric flag")?;
        let n = f.count("the number of nodes in the block")?;
        f.finish()?;
        if parametric > 1 {
            return Err(f.syntax(format!("expected parametric flag 0 or 1, found {parametric}")));
        }
        let mut tags = Vec::with_capacity(n.min(CAPACITY_HINT));
        for _ in 0..n {
            let mut f = cur.fields("a node tag")?;
            tags.push(f.next::<u64>("a node tag")?);
            f.finish()?;
        }
        for tag in tags {
            let mut f = cur.fields("node coordinates `x y z`")?;
            let x: f64 = f.next("a node x coordinate")?;
            let y: f64 = f.next("a node y coordinate")?;
            let z: f64 = f.next("a node z coordinate")?;
            // Parametric coordinates (if any) follow; they are not needed.
            check_planar(cur.file, f.line, tag, x, y, z)?;
            out.push((NodeRec { tag, xy: [x, y] }, f.line));
        }
    }
    if out.len() != n_nodes {
        return Err(cur.syntax(
            header_line,
            format!("header declares {n_nodes} nodes, the blocks hold {}", out.len()),
        ));
    }
    Ok(out)
}

/// 4.1 `$Elements`: entity blocks of `tag nodes...` lines; physical groups come from the
/// block's entity.
pub(super) fn parse_elements(
    cur: &mut Cursor<'_>,
    entities: &HashMap<(u32, i32), Vec<i32>>,
) -> Result<Vec<ElemRec>> {
    let mut f = cur.fields("the element block header")?;
    let n_blocks = f.count("the number of element blocks")?;
    let n_elements = f.count("the number of elements")?;
    f.next::<u64>("the minimum element tag")?;
    f.next::<u64>("the maximum element tag")?;
    f.finish()?;
    let header_line = f.line;
    let mut out = Vec::with_capacity(n_elements.min(CAPACITY_HINT));
    for _ in 0..n_blocks {
        let mut f = cur.fields("an element block `dim tag type count`")?;
        let dim: u32 = f.next("an entity dimension")?;
        let entity: i32 = f.next("an entity tag")?;
        let gmsh_type: u32 = f.next("an element type")?;
        let n = f.count("the number of elements in the block")?;
        f.finish()?;
        if dim > 3 {
            return Err(f.syntax(format!("expected an entity dimension 0-3, found {dim}")));
        }
        let physicals = entities.get(&(dim, entity)).cloned().unwrap_or_default();
        for _ in 0..n {
            let mut f = cur.fields("an element `tag nodes...`")?;
            let tag: u64 = f.next("an element tag")?;
            let mut nodes = Vec::new();
            while let Some(tok) = f.toks.next() {
                nodes.push(
                    tok.parse::<u64>()
                        .map_err(|_| f.syntax(format!("expected a node tag, found {tok:?}")))?,
                );
            }
            out.push(ElemRec {
                tag,
                gmsh_type,
                dim: Some(dim),
                physicals: physicals.clone(),
                nodes,
                line: f.line,
            });
        }
    }
    if out.len() != n_elements {
        return Err(cur.syntax(
            header_line,
            format!("header declares {n_elements} elements, the blocks hold {}", out.len()),
        ));
    }
    Ok(out)
}
