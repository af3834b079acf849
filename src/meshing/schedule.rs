//! Runs independent jobs on the thread pool with a bound on the summed
//! weight of the jobs running at once.
//!
//! Meshing a face holds spade's triangulation and the pass buffers, about
//! 300 bytes per node: two hemispheres of the largest ball meshed side by
//! side doubled the peak memory of `compile` (the seven balls of paper 001:
//! 134 MB on two threads against 93 MB on one). Large jobs start first, and
//! one starts only while the weight already running leaves room for it, so
//! the threads fill up with the small jobs beside the large one instead.
//! Results come back in the order of the input, whatever the scheduling, so
//! the output does not depend on the thread count.

use std::sync::{Condvar, Mutex};

/// Runs `job` on every item, with at most `budget` summed weight running at
/// once (a job heavier than the budget runs alone), and returns the results
/// in the order of `items`.
pub(super) fn run_bounded<T: Send>(
    items: &[(usize, u64)],
    budget: u64,
    job: impl Fn(usize) -> T + Sync,
) -> Vec<(usize, T)> {
    // One worker (a single face, or a one-thread pool): run on the calling
    // thread. Handing a lone job to the pool cost a thread switch, woke the
    // idle workers, and left the face's memory to be freed from another
    // thread's heap during assembly.
    if items.len() <= 1 || rayon::current_num_threads() <= 1 {
        return items.iter().map(|&(key, _)| (key, job(key))).collect();
    }
    // Heaviest first (ties by position: a fixed order, though only memory
    // depends on it).
    let mut order: Vec<usize> = (0..items.len()).collect();
    order.sort_by_key(|&i| (std::cmp::Reverse(items[i].1), i));
    let state = Mutex::new(State {
        pending: order,
        running: 0,
    });
    let room = Condvar::new();
    let results: Vec<Mutex<Option<T>>> = items.iter().map(|_| Mutex::new(None)).collect();
    let workers = rayon::current_num_threads().clamp(1, items.len().max(1));
    rayon::scope(|scope| {
        for _ in 0..workers {
            scope.spawn(|_| {
                while let Some(i) = next(&state, &room, items, budget) {
                    let value = job(items[i].0);
                    if let Ok(mut slot) = results[i].lock() {
                        *slot = Some(value);
                    }
                    if let Ok(mut s) = state.lock() {
                        s.running -= items[i].1;
                    }
                    room.notify_all();
                }
            });
        }
    });
    items
        .iter()
        .zip(results)
        .filter_map(|(&(key, _), slot)| Some((key, slot.into_inner().ok()??)))
        .collect()
}

struct State {
    /// Positions in `items`, heaviest first.
    pending: Vec<usize>,
    running: u64,
}

/// The next item that fits beside the running ones; waits while none does
/// (something is running then, so room comes); `None` when all are taken.
fn next(
    state: &Mutex<State>,
    room: &Condvar,
    items: &[(usize, u64)],
    budget: u64,
) -> Option<usize> {
    let mut s = state.lock().ok()?;
    loop {
        if s.pending.is_empty() {
            return None;
        }
        let fits = s
            .pending
            .iter()
            .position(|&i| s.running == 0 || s.running + items[i].1 <= budget);
        if let Some(k) = fits {
            let i = s.pending.remove(k);
            s.running += items[i].1;
            return Some(i);
        }
        s = room.wait(s).ok()?;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::atomic::{AtomicU64, Ordering};

    #[test]
    fn results_keep_the_input_order_and_the_budget_holds() {
        let items: Vec<(usize, u64)> = (0..40)
            .map(|k| (100 + k, 1 + (k as u64 * 7) % 10))
            .collect();
        let running = AtomicU64::new(0);
        let worst = AtomicU64::new(0);
        let weight = |key: usize| items[key - 100].1;
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(4)
            .build()
            .expect("a pool");
        let out = pool.install(|| {
            run_bounded(&items, 12, |key| {
                let now = running.fetch_add(weight(key), Ordering::SeqCst) + weight(key);
                worst.fetch_max(now, Ordering::SeqCst);
                std::thread::sleep(std::time::Duration::from_millis(1));
                running.fetch_sub(weight(key), Ordering::SeqCst);
                key * 2
            })
        });
        let keys: Vec<usize> = out.iter().map(|&(k, _)| k).collect();
        assert_eq!(keys, (100..140).collect::<Vec<_>>());
        assert!(out.iter().all(|&(k, v)| v == 2 * k));
        assert!(
            worst.load(Ordering::SeqCst) <= 12,
            "{}",
            worst.load(Ordering::SeqCst)
        );
    }

    #[test]
    fn a_lone_job_runs_on_the_calling_thread() {
        let caller = std::thread::current().id();
        let out = run_bounded(&[(7, 5)], 1, |key| (key * 3, std::thread::current().id()));
        assert_eq!(out, vec![(7, (21, caller))]);
    }

    #[test]
    fn a_job_over_the_budget_still_runs() {
        let items = [(0, 50), (1, 1), (2, 1)];
        let out = run_bounded(&items, 10, |key| key + 1);
        assert_eq!(out, vec![(0, 1), (1, 2), (2, 3)]);
    }
}
