//! MSH 2.2 ASCII: `$Nodes` as `tag x y z` lines, `$Elements` with their physical group as
//! the first tag (an element is repeated once per physical group it belongs to).

use super::Result;
use super::ascii::Cursor;
use super::records::{CAPACITY_HINT, ElemRec, NodeRec, check_planar, type_info};

/// 2.2 `$Nodes`: a count, then one `tag x y z` line per node.
pub(super) fn parse_nodes(cur: &mut Cursor<'_>) -> Result<Vec<(NodeRec, usize)>> {
    let mut f = cur.fields("the number of nodes")?;
    let n = f.count("the number of nodes")?;
    f.finish()?;
    let mut out = Vec::with_capacity(n.min(CAPACITY_HINT));
    for _ in 0..n {
        let mut f = cur.fields("a node `tag x y z`")?;
        let tag: u64 = f.next("a node tag")?;
        let x: f64 = f.next("a node x coordinate")?;
        let y: f64 = f.next("a node y coordinate")?;
        let z: f64 = f.next("a node z coordinate")?;
        f.finish()?;
        check_planar(cur.file, f.line, tag, x, y, z)?;
        out.push((NodeRec { tag, xy: [x, y] }, f.line));
    }
    Ok(out)
}

/// 2.2 `$Elements`: a count, then one `tag type ntags tags... nodes...` line per element.
pub(super) fn parse_elements(cur: &mut Cursor<'_>) -> Result<Vec<ElemRec>> {
    let mut f = cur.fields("the number of elements")?;
    let n = f.count("the number of elements")?;
    f.finish()?;
    let mut out = Vec::with_capacity(n.min(CAPACITY_HINT));
    for _ in 0..n {
        let mut f = cur.fields("an element `tag type ntags tags... nodes...`")?;
        let tag: u64 = f.next("an element tag")?;
        let gmsh_type: u32 = f.next("an element type")?;
        let n_tags = f.count("the number of element tags")?;
        let mut tags = Vec::with_capacity(n_tags.min(CAPACITY_HINT));
        for _ in 0..n_tags {
            tags.push(f.next::<i32>("an element tag value")?);
        }
        let mut nodes = Vec::new();
        while let Some(tok) = f.toks.next() {
            nodes.push(
                tok.parse::<u64>()
                    .map_err(|_| f.syntax(format!("expected a node tag, found {tok:?}")))?,
            );
        }
        // Tag 0 is the physical group (0 = none), tag 1 the elementary entity.
        let physicals = match tags.first() {
            Some(&p) if p != 0 => vec![p],
            _ => Vec::new(),
        };
        let dim = type_info(gmsh_type).map(|i| i.1);
        out.push(ElemRec { tag, gmsh_type, dim, physicals, nodes, line: f.line });
    }
    Ok(out)
}
