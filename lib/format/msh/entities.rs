//! `$Entities` (MSH 4.1 only): the geometric entities and their physical tags.
//!
//! ```text
//! $Entities
//! numPoints numCurves numSurfaces numVolumes                      (size_t)
//! pointTag X Y Z numPhysicalTags physicalTag ...                  (int, 3 double, size_t, int...)
//! curveTag minX minY minZ maxX maxY maxZ
//!   numPhysicalTags physicalTag ... numBoundingPoints pointTag ...  (int, 6 double, size_t, int..., size_t, int...)
//! surfaceTag ... numBoundingCurves curveTag ...                   (as curves)
//! volumeTag ... numBoundingSurfaces surfaceTag ...                (as curves)
//! $EndEntities
//! ```
//! In MSH 4.1 an element carries no physical tag of its own: it belongs to the
//! physical groups of its entity `(entityDim, entityTag)`, given here. Only
//! those tags are kept; boxes and boundaries are read and dropped.

use std::collections::HashMap;

use super::cursor::Cursor;
use super::MshError;

/// Physical tags of each entity `(dim, tag)`, in file order.
pub(super) type EntityPhysicals = HashMap<(u8, i32), Vec<i32>>;

pub(super) fn parse(cur: &mut Cursor) -> Result<EntityPhysicals, MshError> {
    cur.section_end = "$EndEntities";
    let mut counts = [0u64; 4];
    for (dim, c) in counts.iter_mut().enumerate() {
        *c = cur.size_t(["the number of points", "the number of curves", "the number of surfaces", "the number of volumes"][dim])?;
    }
    let mut out = EntityPhysicals::new();
    for (dim, &count) in counts.iter().enumerate() {
        for _ in 0..count {
            let tag = cur.int("an entity tag")?;
            let box_values = if dim == 0 { 3 } else { 6 };
            for _ in 0..box_values {
                cur.double("an entity bounding-box coordinate")?;
            }
            let n_physicals = cur.size_t("the number of physical tags")?;
            let mut physicals = Vec::with_capacity(cur.capacity(n_physicals, 2));
            for _ in 0..n_physicals {
                physicals.push(cur.int("a physical tag")?);
            }
            if dim > 0 {
                let n_bounding = cur.size_t("the number of bounding entities")?;
                for _ in 0..n_bounding {
                    cur.int("a bounding entity tag")?;
                }
            }
            out.insert((dim as u8, tag), physicals);
        }
    }
    cur.expect_end()?;
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ascii_entities() {
        let text = b"1 0 1 1\n\
            7 0 0 0 1 5\n\
            3 0 0 0 1 1 0 2 10 11 0\n\
            1 0 0 0 1 1 1 0 1 3\n\
            $EndEntities\n";
        let mut c = Cursor::new("t.msh", text);
        let e = parse(&mut c).unwrap();
        assert_eq!(e[&(0, 7)], vec![5]);
        assert_eq!(e[&(2, 3)], vec![10, 11]);
        assert_eq!(e[&(3, 1)], Vec::<i32>::new());
    }

    #[test]
    fn truncated_entities() {
        let mut c = Cursor::new("t.msh", b"1 0 0 0\n7 0 0");
        let e = parse(&mut c).unwrap_err().to_string();
        assert_eq!(e, "t.msh:2: expected `$EndEntities` before end of file");
    }
}
