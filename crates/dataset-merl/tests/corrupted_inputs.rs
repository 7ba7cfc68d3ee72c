//! Robustness of the loaders a user feeds (issue 19): corrupted copies of a MERL table and of
//! a published NBRDF network (truncated, bit-flipped, header dimensions blasted to 2^31 or
//! 2^40, spliced, noise) give an error naming the input, never a panic or an unbounded
//! allocation. See `test_support::corrupt` for the mutations.

use dataset_merl::{MerlBrdf, Nbrdf};
use test_support::corrupt::{CappedAlloc, fuzz_loader};

/// A MERL file is 35 MB; nothing a loader does may allocate more than 1 GiB at once.
#[global_allocator]
static ALLOC: CappedAlloc = CappedAlloc(1 << 30);

#[test]
fn corrupted_merl_tables_give_errors_not_panics() {
    let table = MerlBrdf::tabulate("seed", |th, td, _| [0.1 + th, 0.2 + td, 0.05]).unwrap();
    let full = table.to_bytes();
    // The header with a few values, so that most mutations reach the header checks quickly,
    // and the whole file (every byte of the payload is a candidate for NaN or negative).
    let seeds = vec![full[..12 + 8 * 64].to_vec(), full];
    let ran = fuzz_loader("merl", &seeds, 400, |b| {
        if let Err(e) = MerlBrdf::from_bytes(b, "fuzz.binary") {
            assert!(e.to_string().contains("fuzz.binary"), "{e}");
        }
    });
    assert!(ran > 400);
}

/// Found by the test above: a header of three 2^24 dimensions overflowed the product the error
/// message prints.
#[test]
fn huge_header_dimensions_are_an_error() {
    let header = [0u8, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1];
    let e = MerlBrdf::from_bytes(&header, "huge.binary").unwrap_err().to_string();
    assert!(e.contains("huge.binary") && e.contains("[16777216, 16777216, 16777216]"), "{e}");
}

#[test]
fn corrupted_nbrdf_networks_give_errors_not_panics() {
    let json = dataset_merl::catalogue::entry("blue-acrylic").unwrap().nbrdf_json();
    let seeds = vec![json.as_bytes().to_vec()];
    fuzz_loader("nbrdf", &seeds, 1500, |b| {
        // A file that is not UTF-8 fails in `read_to_string` before the parser sees it.
        if let Ok(text) = std::str::from_utf8(b)
            && let Err(e) = Nbrdf::from_json(text, "fuzz.json")
        {
            assert!(e.to_string().contains("fuzz.json"), "{e}");
        }
    });
}
