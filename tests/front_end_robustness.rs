//! A deterministic small-scale fuzz of the front end inside the test suite:
//! every fixture truncated, with bytes flipped, ranges deleted and duplicated.
//! The front end must return diagnostics (never panic), and every diagnostic's
//! span must lie inside the source it points into. The cargo-fuzz target in
//! `fuzz/` explores further.

use geomc::diag::render_human;
use geomc::driver::{Options, check_bytes};
use std::path::Path;

struct XorShift(u32);

impl XorShift {
    fn next(&mut self) -> u32 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 17;
        self.0 ^= self.0 << 5;
        self.0
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() as usize) % n.max(1)
    }
}

fn mutations(bytes: &[u8], rng: &mut XorShift) -> Vec<Vec<u8>> {
    let mut out = Vec::new();
    let n = bytes.len();
    for k in 1..=8 {
        out.push(bytes[..n * k / 9].to_vec());
    }
    const INTERESTING: &[u8] = b"<>/=\"'&;![]-.0123456789 \n\xff\xc3";
    for _ in 0..16 {
        let mut m = bytes.to_vec();
        let at = rng.below(n);
        if let Some(b) = m.get_mut(at) {
            *b = INTERESTING[rng.below(INTERESTING.len())];
        }
        out.push(m);
    }
    for _ in 0..4 {
        let (a, b) = (rng.below(n), rng.below(n));
        let (a, b) = (a.min(b), a.max(b));
        let mut deleted = bytes[..a].to_vec();
        deleted.extend_from_slice(&bytes[b..]);
        out.push(deleted);
        let mut doubled = bytes[..b].to_vec();
        doubled.extend_from_slice(&bytes[a..]);
        out.push(doubled);
    }
    out
}

#[test]
fn mutated_fixtures_never_panic_and_spans_stay_in_bounds() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures");
    let mut rng = XorShift(0x9e37_79b9);
    let mut runs = 0;
    for folder in ["valid", "invalid"] {
        let mut paths: Vec<_> = std::fs::read_dir(root.join(folder))
            .expect("fixtures")
            .filter_map(|e| e.ok().map(|e| e.path()))
            .collect();
        paths.sort();
        for path in paths {
            let bytes = std::fs::read(&path).expect("fixture");
            for mutated in mutations(&bytes, &mut rng) {
                let name = path.display().to_string();
                let checked = check_bytes(name.clone(), mutated, &Options::default());
                for d in &checked.diagnostics.items {
                    if let Some(span) = d.span {
                        assert!(
                            span.start <= span.end
                                && span.end as usize <= checked.source.text.len(),
                            "{name}: span {span:?} outside a {}-byte source for {}",
                            checked.source.text.len(),
                            d.code.as_str()
                        );
                    }
                    let _ = render_human(&checked.source, d);
                }
                runs += 1;
            }
        }
    }
    assert!(runs > 5000, "only {runs} mutated inputs");
}
