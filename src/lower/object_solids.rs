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
    /// has several). `last` is the last object of that name
    /// (`resolved.by_name.get`, which the caller has looked up already). A
    /// group without `[k]` stands for its members' (member by member;
    /// `group_members`: the last object's count). Member `k` of a group also
    /// meets an object literally named "name[k]" (a name that is not plain is
    /// only a warning), as the map by formatted name did.
    pub fn of(
        &self,
        resolved: &Resolved,
        name: &str,
        last: Option<usize>,
        member: Option<usize>,
        group_members: Option<usize>,
    ) -> FoundSolids {
        match (member, group_members) {
            (Some(k), _) => self.member_solids(resolved, name, last, k),
            (None, Some(count)) => FoundSolids::List(
                (1..=count)
                    .flat_map(|k| self.member_solids(resolved, name, last, k).into_iter())
                    .collect(),
            ),
            (None, None) => self.own_solids(resolved, last),
        }
    }

    /// The solids of `last` and the objects of its name before it that are
    /// not groups.
    fn own_solids(&self, resolved: &Resolved, last: Option<usize>) -> FoundSolids {
        let is_group = |i: usize| {
            matches!(
                resolved.objects.get(i).and_then(|o| o.geometry.as_ref()),
                Some(Geometry::Group(_))
            )
        };
        let runs = (resolved.by_name.from_last(last))
            .filter(|&i| !is_group(i))
            .map(|i| self.range(i));
        FoundSolids::from_last(runs)
    }

    fn member_solids(
        &self,
        resolved: &Resolved,
        name: &str,
        last: Option<usize>,
        k: usize,
    ) -> FoundSolids {
        let members = (resolved.by_name.from_last(last))
            .filter_map(|i| self.member(resolved, i, k))
            .map(|SolidId(id)| id..id + 1);
        // Only a file with a name ending in `]` can have an object named
        // "name[k]": the others make no string per member reference.
        if !resolved.by_name.has_bracketed_names() {
            return FoundSolids::from_last(members);
        }
        let literal = format!("{name}[{k}]");
        let mut ids: Vec<SolidId> = FoundSolids::from_last(members).into_iter().collect();
        if let Some(object) = resolved.by_name.get(&resolved.objects, &literal) {
            ids.extend(self.own_solids(resolved, Some(object)));
            ids.sort_unstable();
        }
        FoundSolids::List(ids)
    }
}

/// The solids a reference stands for, in id order: one object's run of
/// consecutive ids (nearly every reference: no list is made for it), or a
/// list.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) enum FoundSolids {
    Run(std::ops::Range<u32>),
    List(Vec<SolidId>),
}

impl FoundSolids {
    /// The solids of objects' runs given from the last object to the first
    /// (as the name index walks them). An object's solids come after those
    /// of the objects before it, so the sorted ids are in document order.
    fn from_last(runs: impl Iterator<Item = std::ops::Range<u32>>) -> FoundSolids {
        let mut runs = runs.filter(|r| !r.is_empty());
        let Some(last) = runs.next() else {
            return FoundSolids::Run(0..0);
        };
        let Some(before) = runs.next() else {
            return FoundSolids::Run(last);
        };
        let mut ids: Vec<SolidId> = ([last, before].into_iter().chain(runs))
            .flatten()
            .map(SolidId)
            .collect();
        ids.sort_unstable();
        FoundSolids::List(ids)
    }

    pub fn len(&self) -> usize {
        match self {
            FoundSolids::Run(run) => run.len(),
            FoundSolids::List(ids) => ids.len(),
        }
    }

    pub fn first(&self) -> Option<SolidId> {
        self.iter().next()
    }

    pub fn iter(&self) -> impl Iterator<Item = SolidId> + '_ {
        let (run, list) = match self {
            FoundSolids::Run(run) => (run.clone(), &[][..]),
            FoundSolids::List(ids) => (0..0, ids.as_slice()),
        };
        run.map(SolidId).chain(list.iter().copied())
    }
}

impl IntoIterator for FoundSolids {
    type Item = SolidId;
    type IntoIter = std::iter::Chain<
        std::iter::Map<std::ops::Range<u32>, fn(u32) -> SolidId>,
        std::vec::IntoIter<SolidId>,
    >;

    fn into_iter(self) -> Self::IntoIter {
        let (run, list) = match self {
            FoundSolids::Run(run) => (run, Vec::new()),
            FoundSolids::List(ids) => (0..0, ids),
        };
        run.map(SolidId as fn(u32) -> SolidId).chain(list)
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

    /// What a subdomain's `<solid ref>` finds: the last object of the name
    /// looked up first, as `build_tree` does.
    fn find(
        table: &ObjectSolids,
        resolved: &Resolved,
        name: &str,
        member: Option<usize>,
        group_members: Option<usize>,
    ) -> Vec<SolidId> {
        let last = resolved.by_name.get(&resolved.objects, name);
        let found = table.of(resolved, name, last, member, group_members);
        assert_eq!(found.len(), found.iter().count());
        assert_eq!(found.first(), found.iter().next());
        let by_value: Vec<SolidId> = found.clone().into_iter().collect();
        assert_eq!(by_value, found.iter().collect::<Vec<_>>());
        by_value
    }

    /// The solids of a reference by scanning every object in order: what the
    /// table of vectors by formatted name found.
    fn scanned(
        objects: &[ResolvedObject],
        start: &[u32],
        name: &str,
        member: Option<usize>,
        group_members: Option<usize>,
    ) -> Vec<SolidId> {
        let own = |name: &str| -> Vec<SolidId> {
            (0..objects.len())
                .filter(|&i| objects[i].name == name)
                .filter(|&i| !matches!(objects[i].geometry, Some(Geometry::Group(_))))
                .flat_map(|i| (start[i]..start[i + 1]).map(SolidId))
                .collect()
        };
        let member_of = |k: usize| -> Vec<SolidId> {
            let mut found = Vec::new();
            for i in (0..objects.len()).filter(|&i| objects[i].name == name) {
                let Some(Geometry::Group(members)) = &objects[i].geometry else {
                    continue;
                };
                let solid = |m: &Geometry| matches!(m, Geometry::Solid(_));
                if k >= 1 && members.get(k - 1).is_some_and(solid) {
                    let before = members[..k - 1].iter().filter(|m| solid(m)).count();
                    found.push(SolidId(start[i] + before as u32));
                }
            }
            let literal = own(&format!("{name}[{k}]"));
            if objects.iter().any(|o| o.name == format!("{name}[{k}]")) {
                found.extend(literal);
                found.sort_unstable();
            }
            found
        };
        match (member, group_members) {
            (Some(k), _) => member_of(k),
            (None, Some(count)) => (1..=count).flat_map(member_of).collect(),
            (None, None) => own(name),
        }
    }

    #[test]
    fn references_find_what_a_scan_of_every_object_finds() {
        let mut rng = crate::test_rng::TestRng::new(0x0b1e_c750);
        const NAMES: &[&str] = &["a", "b", "g", "g[1]", "g[2]", "a[3]", "c"];
        let points = || Geometry::Points {
            points: Vec::new(),
            partial: Vec::new(),
        };
        let (mut runs, mut lists, mut nonempty) = (0, 0, 0);
        for _ in 0..3_000 {
            let objects: Vec<ResolvedObject> = (0..1 + rng.below(8))
                .map(|_| {
                    let geometry = match rng.below(5) {
                        0 => None,
                        1 => Some(points()),
                        2 => Some(Geometry::Group(
                            (0..rng.below(5))
                                .map(|_| if rng.below(3) == 0 { points() } else { ball() })
                                .collect(),
                        )),
                        _ => Some(ball()),
                    };
                    object(NAMES[rng.below(NAMES.len())], geometry)
                })
                .collect();
            let counts: Vec<usize> = (objects.iter())
                .map(|o| match &o.geometry {
                    Some(Geometry::Solid(_)) => 1,
                    Some(Geometry::Group(members)) => (members.iter())
                        .filter(|m| matches!(m, Geometry::Solid(_)))
                        .count(),
                    _ => 0,
                })
                .collect();
            let mut start = vec![0u32];
            for n in &counts {
                start.push(start[start.len() - 1] + *n as u32);
            }
            let (resolved, table) = lowered(objects.clone(), &counts);
            for name in NAMES {
                for member in [None, Some(0), Some(1), Some(2), Some(3), Some(9)] {
                    for group in [None, Some(1), Some(3)] {
                        let found = find(&table, &resolved, name, member, group);
                        let expected = scanned(&objects, &start, name, member, group);
                        assert_eq!(found, expected, "{name} {member:?} {group:?} {objects:?}");
                        let last = resolved.by_name.get(&resolved.objects, name);
                        match table.of(&resolved, name, last, member, group) {
                            FoundSolids::Run(_) => runs += 1,
                            FoundSolids::List(_) => lists += 1,
                        }
                        nonempty += usize::from(!found.is_empty());
                    }
                }
            }
        }
        // Both forms and many non-empty answers come up.
        assert!(
            runs > 10_000 && lists > 10_000 && nonempty > 10_000,
            "{runs} {lists} {nonempty}"
        );
    }

    #[test]
    fn one_objects_solids_are_a_run_without_a_list() {
        let (resolved, table) = lowered(
            vec![
                object("a", Some(ball())),
                object("g", Some(Geometry::Group(vec![ball(), ball()]))),
                object("b", Some(ball())),
                object("a", None),
            ],
            &[1, 2, 1, 0],
        );
        let of = |name: &str, member| {
            let last = resolved.by_name.get(&resolved.objects, name);
            table.of(&resolved, name, last, member, None)
        };
        assert_eq!(of("b", None), FoundSolids::Run(3..4));
        // The second "a" failed: only the first's solid is found.
        assert_eq!(of("a", None), FoundSolids::Run(0..1));
        assert_eq!(of("g", Some(2)), FoundSolids::Run(2..3));
        assert_eq!(of("g", None), FoundSolids::Run(0..0));
        assert_eq!(of("c", None), FoundSolids::Run(0..0));
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
        assert_eq!(find(&table, &resolved, "a", None, None), ids(&[0]));
        assert_eq!(find(&table, &resolved, "b", None, None), ids(&[4]));
        assert_eq!(find(&table, &resolved, "failed", None, None), ids(&[]));
        assert_eq!(find(&table, &resolved, "row", Some(1), None), ids(&[1]));
        // Member 2 is no solid; members 3 and 4 come after it.
        assert_eq!(find(&table, &resolved, "row", Some(2), None), ids(&[]));
        assert_eq!(find(&table, &resolved, "row", Some(4), None), ids(&[3]));
        assert_eq!(find(&table, &resolved, "row", Some(0), None), ids(&[]));
        assert_eq!(find(&table, &resolved, "row", Some(5), None), ids(&[]));
        assert_eq!(
            find(&table, &resolved, "row", None, Some(4)),
            ids(&[1, 2, 3])
        );
        // A group's own name (no member) stands for no solid of its own.
        assert_eq!(find(&table, &resolved, "row", None, None), ids(&[]));
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
        assert_eq!(find(&table, &resolved, "a", None, None), ids(&[0, 3]));
        // "g[2]" written as a name is met by member 2 of g, as before.
        assert_eq!(find(&table, &resolved, "g", Some(2), None), ids(&[2, 4]));
        assert_eq!(find(&table, &resolved, "g", None, Some(2)), ids(&[1, 2, 4]));
    }
}
