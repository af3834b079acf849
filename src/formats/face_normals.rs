//! The vertex normals of one face of an expanded group, as the GLB writer
//! streams them: each vertex's sum of its triangles' area-weighted normals
//! in triangle order, made unit in `f64` (the face's direction for a zero
//! sum) and written as `f32`, vertices in first-use order.
//!
//! A large face is taken in blocks of triangles: the next block's triangle
//! normals are computed on another thread while this block's are added into
//! the vertex sums, and the finished sums are made unit a run at a time on
//! all threads. Scratch is bounded (two blocks of triangle normals, one run
//! of units, under 250 kB) beside the face's sums. Every sum is formed by the same
//! additions in the same order as on one thread, so the bytes do not depend
//! on the thread count.

use super::groups::{add, triangle_normal, unit};
use crate::mesh::Mesh;
use rayon::prelude::*;

/// Triangles per block (their normals: 96 kB). Scratch is kept small:
/// blocks and runs of 192 kB raised the compile's peak by half a megabyte.
const BLOCK: usize = 4096;

/// Faces with fewer triangles are summed on one thread: a block's hand-over
/// costs more than it saves.
pub(crate) const BLOCKED_MIN: usize = 2 * BLOCK;

/// Normals made unit and handed out at a time (48 kB of `f32`).
const RUN: usize = 4096;

/// Vertices per parallel piece of a run.
const PIECE: usize = 1024;

/// What a face's sums are formed into and from: the expander's node table
/// (a node's entry is `(stamp, vertex)` while the face's stamp is current)
/// and the face's sums, one per vertex.
pub(crate) struct FaceSums<'s> {
    pub slot: &'s mut [(u32, u32)],
    pub stamp: u32,
    pub sums: &'s mut Vec<[f64; 3]>,
}

/// Reused between faces: the blocks' triangle normals and a run of units.
#[derive(Default)]
pub(crate) struct Scratch {
    normals: [Vec<[f64; 3]>; 2],
    run: Vec<[f32; 3]>,
}

/// One face's unit normals, handed to `emit` a run at a time in vertex
/// order. `blocked`: the next block's triangle normals are computed beside
/// the current block's sums ([`BLOCKED_MIN`] and more than one thread is
/// when that pays; the numbers are the same either way).
pub(crate) fn face_normals<E>(
    mesh: &Mesh,
    triangles: &[[u32; 3]],
    flip: bool,
    into: FaceSums,
    blocked: bool,
    scratch: &mut Scratch,
    emit: &mut impl FnMut(&[[f32; 3]]) -> Result<(), E>,
) -> Result<(), E> {
    let FaceSums { slot, stamp, sums } = into;
    sums.clear();
    let mut total = [0.0; 3];
    if blocked {
        let [mut current, mut next] = std::mem::take(&mut scratch.normals);
        let mut blocks = triangles.chunks(BLOCK);
        let first = blocks.next().unwrap_or_default();
        triangle_normals(mesh, first, flip, &mut current);
        let mut block = first;
        loop {
            let following = blocks.next();
            rayon::join(
                || {
                    if let Some(b) = following {
                        triangle_normals(mesh, b, flip, &mut next);
                    }
                },
                || {
                    for (&tri, &n) in block.iter().zip(&current) {
                        total = add(total, n);
                        add_to_vertices(slot, stamp, sums, oriented(tri, flip), n);
                    }
                },
            );
            let Some(b) = following else { break };
            block = b;
            std::mem::swap(&mut current, &mut next);
        }
        scratch.normals = [current, next];
    } else {
        for &tri in triangles {
            let tri = oriented(tri, flip);
            let n = triangle_normal(mesh, tri);
            total = add(total, n);
            add_to_vertices(slot, stamp, sums, tri, n);
        }
    }
    let fallback = unit(total).unwrap_or([0.0, 0.0, 1.0]);
    emit_units(sums, fallback, &mut scratch.run, emit)
}

/// A triangle in the requested orientation (as `groups::oriented`).
#[inline(always)]
fn oriented([a, b, c]: [u32; 3], flip: bool) -> [u32; 3] {
    if flip { [a, c, b] } else { [a, b, c] }
}

/// The block's triangle normals, in order, into `out`.
fn triangle_normals(mesh: &Mesh, block: &[[u32; 3]], flip: bool, out: &mut Vec<[f64; 3]>) {
    out.clear();
    out.extend(
        block
            .iter()
            .map(|&tri| triangle_normal(mesh, oriented(tri, flip))),
    );
}

/// Adds a triangle's normal to its corners' sums; a corner new to the face
/// becomes the next vertex, its sum starting from zero (`0.0 + n`, not `n`:
/// the sign of a zero sum must be what the plain sums give).
#[inline(always)]
fn add_to_vertices(
    slot: &mut [(u32, u32)],
    stamp: u32,
    sums: &mut Vec<[f64; 3]>,
    tri: [u32; 3],
    n: [f64; 3],
) {
    for node in tri {
        let entry = &mut slot[node as usize];
        if entry.0 != stamp {
            *entry = (stamp, sums.len() as u32);
            sums.push(add([0.0; 3], n));
        } else {
            let s = &mut sums[entry.1 as usize];
            *s = add(*s, n);
        }
    }
}

/// The sums made unit and `f32`, handed out [`RUN`] at a time; a long run
/// is made on all threads in pieces.
fn emit_units<E>(
    sums: &[[f64; 3]],
    fallback: [f64; 3],
    run: &mut Vec<[f32; 3]>,
    emit: &mut impl FnMut(&[[f32; 3]]) -> Result<(), E>,
) -> Result<(), E> {
    for chunk in sums.chunks(RUN) {
        // Every value is written below: resizing fills only when it grows.
        run.resize(chunk.len(), [0.0; 3]);
        if chunk.len() > PIECE {
            run.par_chunks_mut(PIECE)
                .zip(chunk.par_chunks(PIECE))
                .for_each(|(out, sums)| units(sums, fallback, out));
        } else {
            units(chunk, fallback, run);
        }
        emit(run)?;
    }
    Ok(())
}

/// `groups::unit_f32` of each sum.
fn units(sums: &[[f64; 3]], fallback: [f64; 3], out: &mut [[f32; 3]]) {
    for (o, &s) in out.iter_mut().zip(sums) {
        *o = unit(s).unwrap_or(fallback).map(|c| c as f32);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::formats::groups::Expander;
    use crate::mesh::MeshFace;

    /// A wavy sheet of `rows` × `columns` cells, two triangles each, cut
    /// into a large face (rows taken in a scrambled order, so its nodes do
    /// not first appear in their own order) and a small one sharing its
    /// edge. The fourth node from the end sits in one triangle of no area
    /// (a zero sum: its normal is the face's direction); the last three
    /// make a triangle of their own whose normal has a `-0.0` part.
    fn sheet(rows: u32, columns: u32) -> Mesh {
        let width = columns + 1;
        let mut nodes = Vec::new();
        for j in 0..=rows {
            for i in 0..width {
                let (x, y) = (f64::from(i) * 0.013, f64::from(j) * 0.011);
                nodes.push([x, y, (3.0 * x).sin() * (2.0 * y).cos()]);
            }
        }
        let at = |i: u32, j: u32| j * width + i;
        let cells = |j: u32| {
            (0..columns).flat_map(move |i| {
                let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i, j + 1), at(i + 1, j + 1));
                [[a, b, d], [a, d, c]]
            })
        };
        let large_rows = rows - 3;
        let mut large: Vec<[u32; 3]> = (0..large_rows)
            .map(|j| (j * 7919) % large_rows)
            .flat_map(cells)
            .collect();
        let lone = nodes.len() as u32;
        nodes.push([0.5, 0.5, 0.5]);
        large.insert(BLOCK + 5, [lone, lone, 0]);
        // A triangle of its own whose normal is (1, 0, -0.0).
        let p = nodes.len() as u32;
        nodes.extend([[2.0, 0.0, 0.0], [2.0, 1.0, 0.0], [2.0, -1.0, 1.0]]);
        large.insert(3 * BLOCK - 1, [p, p + 1, p + 2]);
        let small = (large_rows..rows).flat_map(cells).collect();
        let face = |name: &str, triangles| MeshFace {
            name: name.into(),
            triangles,
            boundary: Vec::new(),
        };
        Mesh {
            dimension: 3,
            nodes,
            faces: vec![face("large", large), face("small", small)],
            ..Mesh::default()
        }
    }

    /// The normals' bytes as `each_normal_with` hands them out.
    fn normal_bytes(mesh: &Mesh, faces: &[(u32, bool)], blocked: bool) -> Vec<u8> {
        let mut bytes = Vec::new();
        let mut sums = Vec::new();
        Expander::new(mesh)
            .each_normal_with(faces, &mut sums, |_| blocked, &mut |run| {
                for c in run.as_flattened() {
                    bytes.extend_from_slice(&c.to_le_bytes());
                }
                Ok::<(), ()>(())
            })
            .expect("no emit fails");
        bytes
    }

    /// Blocked sums, made unit in parallel runs, give the bytes of the
    /// plain serial sums and of the whole expansion, whichever way the
    /// faces are turned and on one thread or two.
    #[test]
    fn blocked_normals_have_the_bytes_of_the_plain_sums() {
        let mesh = sheet(130, 100);
        let large = mesh.faces[0].triangles.len();
        // More than three blocks (so at least `BLOCKED_MIN`), the last one short.
        assert!(large > 3 * BLOCK && !large.is_multiple_of(BLOCK));
        for faces in [[(0, false), (1, true)], [(1, false), (0, true)]] {
            let plain = normal_bytes(&mesh, &faces, false);
            let expanded: Vec<u8> = Expander::new(&mesh)
                .expand(&faces)
                .normals
                .iter()
                .flat_map(|n| n.map(|c| c as f32))
                .flat_map(f32::to_le_bytes)
                .collect();
            assert_eq!(plain.len(), 12 * (101 * 131 + 4 + 101));
            assert!(plain == expanded, "plain sums against the expansion");
            let pool = |threads| {
                rayon::ThreadPoolBuilder::new()
                    .num_threads(threads)
                    .build()
                    .expect("a thread pool")
            };
            for threads in [1, 2, 3] {
                let blocked = pool(threads).install(|| normal_bytes(&mesh, &faces, true));
                assert!(blocked == plain, "blocked on {threads} threads");
            }
        }
    }

    /// The zero sum takes the face's direction and a sum starting from a
    /// `-0.0` part keeps the sign of zero the plain sums give (`0.0 + n`):
    /// checked against numbers formed here from the definition.
    #[test]
    fn zero_sums_and_signed_zeros_follow_the_definition() {
        let mesh = sheet(60, 300);
        let triangles = &mesh.faces[0].triangles;
        assert!(triangles.len() >= BLOCKED_MIN);
        let p = mesh.nodes.len() as u32 - 3;
        let signed = triangle_normal(&mesh, [p, p + 1, p + 2]);
        assert_eq!(signed.map(f64::to_bits), [1.0, 0.0, -0.0].map(f64::to_bits));
        let mut sums: Vec<[f64; 3]> = Vec::new();
        let mut total = [0.0; 3];
        let mut vertex = vec![u32::MAX; mesh.nodes.len()];
        for &tri in triangles {
            let n = triangle_normal(&mesh, tri);
            total = add(total, n);
            for v in tri {
                if vertex[v as usize] == u32::MAX {
                    vertex[v as usize] = sums.len() as u32;
                    sums.push([0.0; 3]);
                }
                let s = &mut sums[vertex[v as usize] as usize];
                *s = add(*s, n);
            }
        }
        let direction = unit(total).expect("a direction");
        let want: Vec<u8> = sums
            .iter()
            .flat_map(|&s| unit(s).unwrap_or(direction).map(|c| c as f32))
            .flat_map(f32::to_le_bytes)
            .collect();
        let got = normal_bytes(&mesh, &[(0, false)], true);
        assert!(got == want, "blocked normals against the definition");
        let lone = vertex[mesh.nodes.len() - 4] as usize;
        let bytes_of = |v: usize| &got[12 * v..12 * v + 12];
        let direction_bytes: Vec<u8> = direction
            .iter()
            .flat_map(|&c| (c as f32).to_le_bytes())
            .collect();
        assert_eq!(bytes_of(lone), direction_bytes.as_slice());
        // That triangle's corners: (1, 0, +0.0), not its normal's -0.0.
        let corner = vertex[p as usize] as usize;
        let want_corner: Vec<u8> = [1.0f32, 0.0, 0.0]
            .iter()
            .flat_map(|c| c.to_le_bytes())
            .collect();
        assert_eq!(bytes_of(corner), want_corner.as_slice());
    }
}
