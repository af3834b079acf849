//! Where a face's surface or an edge's curve is kept: its own, or made on
//! demand from the shape of the primitive solid whose canonical boundary the
//! entity is (face or edge `local` of `geom::solid_carriers`). On files of many
//! primitives a copy of every carrier was a fifth of the memory peak.

use super::{Solid, SolidId};
use crate::geom::{Curve, Surface};
use std::borrow::Cow;

#[derive(Debug, Clone, PartialEq)]
pub enum Carrier<T> {
    Own(Box<T>),
    /// Entity `local` of the boundary of `solid` (in `Model::solids`).
    Primitive {
        solid: SolidId,
        local: u32,
    },
}

impl<T> Carrier<T> {
    pub fn own(value: T) -> Carrier<T> {
        Carrier::Own(Box::new(value))
    }

    /// Face or edge `local` of the canonical boundary of `solid`.
    pub fn primitive(solid: SolidId, local: usize) -> Carrier<T> {
        Carrier::Primitive {
            solid,
            local: local as u32,
        }
    }

    /// The carrier when it is kept here (a surface or curve no primitive
    /// makes, such as a patch or a trimmed surface, is always).
    pub fn owned(&self) -> Option<&T> {
        match self {
            Carrier::Own(value) => Some(value),
            Carrier::Primitive { .. } => None,
        }
    }
}

impl<T: Clone> Carrier<T> {
    /// The carrier for changing: a primitive's is made and kept from then on.
    pub fn to_mut(
        &mut self,
        solids: &[Solid],
        make: impl Fn(&Solid, usize) -> Option<T>,
    ) -> &mut T {
        if let Carrier::Primitive { solid, local } = *self {
            *self = Carrier::own(primitive(solids, solid, local, make));
        }
        match self {
            Carrier::Own(value) => value,
            Carrier::Primitive { .. } => unreachable!("made owned above"),
        }
    }

    fn get<'a>(
        &'a self,
        solids: &[Solid],
        make: impl Fn(&Solid, usize) -> Option<T>,
    ) -> Cow<'a, T> {
        match self {
            Carrier::Own(value) => Cow::Borrowed(value),
            &Carrier::Primitive { solid, local } => {
                Cow::Owned(primitive(solids, solid, local, make))
            }
        }
    }
}

/// A primitive's carrier. Lowering makes a `Primitive` carrier only for an
/// entity the solid's canonical boundary has, and solids are never removed,
/// so the lookup cannot fail on any input (not a user-controlled value).
#[allow(clippy::expect_used)]
fn primitive<T>(
    solids: &[Solid],
    solid: SolidId,
    local: u32,
    make: impl Fn(&Solid, usize) -> Option<T>,
) -> T {
    solids
        .get(solid.index())
        .and_then(|s| make(s, local as usize))
        .expect("a primitive carrier names a face or edge of a lowered solid")
}

impl Carrier<Surface> {
    /// The surface, made from its solid's shape when it is a primitive's.
    pub fn surface<'a>(&'a self, solids: &[Solid]) -> Cow<'a, Surface> {
        self.get(solids, |s, local| s.shape.face_surface(local))
    }

    pub fn surface_mut(&mut self, solids: &[Solid]) -> &mut Surface {
        self.to_mut(solids, |s, local| s.shape.face_surface(local))
    }
}

impl Carrier<Curve> {
    /// The curve, made from its solid's shape when it is a primitive's.
    pub fn curve<'a>(&'a self, solids: &[Solid]) -> Cow<'a, Curve> {
        self.get(solids, |s, local| s.shape.edge_curve(local))
    }

    pub fn curve_mut(&mut self, solids: &[Solid]) -> &mut Curve {
        self.to_mut(solids, |s, local| s.shape.edge_curve(local))
    }
}
