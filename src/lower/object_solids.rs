//! The solids each resolved object lowered to, for subdomains' `<solid ref>`.
//! An object's solids get consecutive ids (a group's solid members in member
//! order), so one start per object finds them: on files of many primitives a
//! map from a `String` per object to a vector per object was a tenth of the
//! memory lowering adds.

use crate::ir::SolidId;
use crate::resolve::{Geometry, Resolved};

#[derive(Debug, Default)]
pub(crate) struct ObjectSolids {
    /// `start[i]..start[i + 1]`: the solids of object `i`.
    start: Vec<u32>,
}

impl ObjectSolids {
    /// Called before each object is lowered, in document order, with the
    /// number of solids lowered so far; and once more after the last.
    pub fn begin_object(&mut self, solids: usize) {
        self.start.push(solids as u32);
    }

    fn range(&self, object: usize) -> std::ops::Range<u32> {
        match (self.start.get(object), self.start.get(object + 1)) {
            (Some(&a), Some(&b)) => a..b,
            _ => 0..0,
        }
    }

    /// The solids of member `k` (from 1) of object `object`, when it is a
    /// group whose member `k` is a solid.
    fn member(&self, resolved: &Resolved, object: usize, k: usize) -> Option<SolidId> {
        let Some(Geometry::Group(members)) = &resolved.objects.get(object)?.geometry else {
            return None;
        };
        let before = members.get(..k.checked_sub(1)?)?;
        let Some(Geometry::Solid(_)) = members.get(k - 1) else {
            return None;
        };
        let solids_before = before
            .iter()
            .filter(|m| matches!(m, Geometry::Solid(_)))
            .count();
        Some(SolidId(self.range(object).start + solids_before as u32))
    }

    /// The solids a reference `name` (`name[k]` with `member`) stands for:
    /// those of every object of that name, in id order (a name given twice
    /// has several). A group without `[k]` stands for its members' (member by
    /// member; `group_members`: the last object's count). Member `k` of a
    /// group also meets an object literally named "name[k]" (a name that is
    /// not plain is only a warning), as the map by formatted name did.
    pub fn of(
        &self,
        resolved: &Resolved,
        name: &str,
        member: Option<usize>,
        group_members: Option<usize>,
    ) -> Vec<SolidId> {
        match (member, group_members) {
            (Some(k), _) => self.member_solids(resolved, name, k),
            (None, Some(count)) => (1..=count)
                .flat_map(|k| self.member_solids(resolved, name, k))
                .collect(),
            (None, None) => self.own_solids(resolved, name),
        }
    }

    /// The solids of the objects named `name` that are not groups.
    fn own_solids(&self, resolved: &Resolved, name: &str) -> Vec<SolidId> {
        let objects = resolved.by_name.all(&resolved.objects, name);
        let is_group = |i: usize| {
            matches!(
                resolved.objects.get(i).and_then(|o| o.geometry.as_ref()),
                Some(Geometry::Group(_))
            )
        };
        (objects.iter())
            .filter(|&&i| !is_group(i))
            .flat_map(|&i| self.range(i).map(SolidId))
            .collect()
    }

    fn member_solids(&self, resolved: &Resolved, name: &str, k: usize) -> Vec<SolidId> {
        let objects = resolved.by_name.all(&resolved.objects, name);
        let mut ids: Vec<SolidId> = (objects.iter())
            .filter_map(|&i| self.member(resolved, i, k))
            .collect();
        let literal = format!("{name}[{k}]");
        if resolved.object(&literal).is_some() {
            ids.extend(self.own_solids(resolved, &literal));
            ids.sort_unstable();
        }
        ids
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::{Frame, SolidShape};
    use crate::resolve::{NameIndex, ResolvedObject};

    fn ball() -> Geometry {
        Geometry::Solid(SolidShape::Ball {
            frame: Frame::identity(),
        })
    }

    fn object(name: &str, geometry: Option<Geometry>) -> ResolvedObject {
        ResolvedObject {
            name: name.to_string(),
            span: crate::span::Span::default(),
            geometry,
        }
    }

    /// Objects and the number of solids each lowered to, as `lower` counts them.
    fn lowered(objects: Vec<ResolvedObject>, solids: &[usize]) -> (Resolved, ObjectSolids) {
        let resolved = Resolved {
            dimension: 3,
            by_name: NameIndex::build(&objects),
            objects,
            parameters: Vec::new(),
            subdomain_areas: Vec::new(),
        };
        let mut table = ObjectSolids::default();
        let mut total = 0;
        for n in solids {
            table.begin_object(total);
            total += n;
        }
        table.begin_object(total);
        (resolved, table)
    }

    fn ids(list: &[u32]) -> Vec<SolidId> {
        list.iter().copied().map(SolidId).collect()
    }

    #[test]
    fn objects_and_group_members_find_their_solids() {
        // a: a ball (solid 0); failed: nothing; row: a group of a ball, a
        // point set and two balls (solids 1, 2, 3); b: a ball (solid 4).
        let points = Geometry::Points {
            points: Vec::new(),
            partial: Vec::new(),
        };
        let row = Geometry::Group(vec![ball(), points, ball(), ball()]);
        let (resolved, table) = lowered(
            vec![
                object("a", Some(ball())),
                object("failed", None),
                object("row", Some(row)),
                object("b", Some(ball())),
            ],
            &[1, 0, 3, 1],
        );
        assert_eq!(table.of(&resolved, "a", None, None), ids(&[0]));
        assert_eq!(table.of(&resolved, "b", None, None), ids(&[4]));
        assert_eq!(table.of(&resolved, "failed", None, None), ids(&[]));
        assert_eq!(table.of(&resolved, "row", Some(1), None), ids(&[1]));
        // Member 2 is no solid; members 3 and 4 come after it.
        assert_eq!(table.of(&resolved, "row", Some(2), None), ids(&[]));
        assert_eq!(table.of(&resolved, "row", Some(4), None), ids(&[3]));
        assert_eq!(table.of(&resolved, "row", Some(0), None), ids(&[]));
        assert_eq!(table.of(&resolved, "row", Some(5), None), ids(&[]));
        assert_eq!(table.of(&resolved, "row", None, Some(4)), ids(&[1, 2, 3]));
        // A group's own name (no member) stands for no solid of its own.
        assert_eq!(table.of(&resolved, "row", None, None), ids(&[]));
    }

    #[test]
    fn a_name_given_twice_finds_every_objects_solids_in_order() {
        let (resolved, table) = lowered(
            vec![
                object("a", Some(ball())),
                object("g", Some(Geometry::Group(vec![ball(), ball()]))),
                object("a", Some(ball())),
                object("g[2]", Some(ball())),
            ],
            &[1, 2, 1, 1],
        );
        assert_eq!(table.of(&resolved, "a", None, None), ids(&[0, 3]));
        // "g[2]" written as a name is met by member 2 of g, as before.
        assert_eq!(table.of(&resolved, "g", Some(2), None), ids(&[2, 4]));
        assert_eq!(table.of(&resolved, "g", None, Some(2)), ids(&[1, 2, 4]));
    }
}
