//! Freeing a large model on the rayon threads. A file of many primitives
//! lowers to hundreds of thousands of entities, each with a shared name and
//! some with lists of their own; freeing them one by one on the thread that
//! drops the model was a serial tail of every check (about 4% of the
//! instructions of `geomc validate` on 100,000 primitives, with the other
//! core idle). Small models drop as before.

use super::Model;
use rayon::prelude::*;

/// Entities (vertices, edges, faces, solids and subdomains together) from
/// which a model is freed in parallel; below it the threads cost more than
/// they save.
const PARALLEL_FROM: usize = 8192;

/// Elements one parallel job frees.
const PER_JOB: usize = 2048;

impl Drop for Model {
    fn drop(&mut self) {
        let entities = self.vertices.len()
            + self.edges.len()
            + self.faces.len()
            + self.solids.len()
            + self.subdomains.len();
        if entities < PARALLEL_FROM {
            return;
        }
        // Each list is freed element by element on the workers; what is left
        // (the other lists, the emptied vectors' buffers) drops as usual.
        free_in_parallel(std::mem::take(&mut self.faces));
        free_in_parallel(std::mem::take(&mut self.solids));
        free_in_parallel(std::mem::take(&mut self.edges));
        free_in_parallel(std::mem::take(&mut self.vertices));
        free_in_parallel(std::mem::take(&mut self.subdomains));
    }
}

fn free_in_parallel<T: Send>(items: Vec<T>) {
    items.into_par_iter().with_min_len(PER_JOB).for_each(drop);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::{Curve, Point3};
    use crate::ir::{Carrier, Dimension, Edge, EntityName, LocalName, Subdomain, Vertex, VertexId};
    use crate::test_threads::on_threads;
    use std::sync::Arc;

    /// A model of `n` vertices and `n` edges named after one shared base,
    /// and `n / 4` subdomains.
    fn model(base: &Arc<Box<str>>, n: usize) -> Model {
        let mut model = Model::empty(Dimension::Three);
        for k in 0..n as u32 {
            model.vertices.push(Vertex {
                name: EntityName::local(base, LocalName::Vertex(k + 1)),
                position: Point3::new(k as f64, 0.0, 0.0),
            });
            let a = Point3::new(k as f64, 0.0, 0.0);
            model.edges.push(Edge {
                name: EntityName::local(base, LocalName::Edge(k + 1)),
                carrier: Carrier::own(Curve::Segment { a, b: a }),
                begin: VertexId(k),
                end: VertexId(k),
            });
        }
        model.subdomains = (0..n / 4)
            .map(|k| Subdomain {
                name: format!("d{k}"),
                ..Subdomain::default()
            })
            .collect();
        model
    }

    #[test]
    fn large_and_small_models_free_every_entity_on_any_thread_count() {
        let base: Arc<Box<str>> = Arc::new("solid".into());
        for n in [10, PARALLEL_FROM, 3 * PARALLEL_FROM] {
            for threads in [1, 2, 3] {
                let model = model(&base, n);
                assert_eq!(Arc::strong_count(&base), 1 + 2 * n);
                on_threads(threads, || drop(model));
                // Every entity's name was released: only this test's is left.
                assert_eq!(
                    Arc::strong_count(&base),
                    1,
                    "{n} entities, {threads} threads"
                );
            }
        }
        // A clone is freed on its own and leaves the original whole.
        let original = model(&base, PARALLEL_FROM);
        let copy = original.clone();
        drop(copy);
        assert_eq!(Arc::strong_count(&base), 1 + 2 * PARALLEL_FROM);
        assert_eq!(original.vertices[7].name, "solid.v8");
        assert_eq!(original.subdomains.len(), PARALLEL_FROM / 4);
    }
}
