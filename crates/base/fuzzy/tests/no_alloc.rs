//! The hot paths of Mamdani inference (Mamdani & Assilian 1975) do not
//! allocate — the promise the paper's §4.3 controller loop relies on —
//! checked with a counting global allocator.

mod common;

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

use common::table1;

struct Counting;

thread_local! {
    static ALLOCATIONS: Cell<usize> = const { Cell::new(0) };
}

// SAFETY: forwards every call unchanged to the system allocator; only counts.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let _ = ALLOCATIONS.try_with(|c| c.set(c.get() + 1));
        // SAFETY: same contract as our caller's.
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: same contract as our caller's.
        unsafe { System.dealloc(ptr, layout) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

fn allocations() -> usize {
    ALLOCATIONS.with(Cell::get)
}

#[test]
fn infer_and_infer_with_do_not_allocate() {
    let sys = table1::system();
    let mut scratch = sys.scratch();
    let points = [
        [0.0, 0.0],
        [0.1, -7.0],
        [0.6, 45.0],
        [-0.2925, 12.3],
        [-9.0, 1e9],
    ];
    let before = allocations();
    let mut sum = 0.0;
    for x in &points {
        sum += sys.infer(x).unwrap();
        sum += sys.infer_with(x, &mut scratch).unwrap();
    }
    let after = allocations();
    assert!(sum.is_finite());
    assert_eq!(after - before, 0, "inference allocated");
    // The counter works: a trace does allocate.
    let _ = sys.infer_traced(&[0.1, 0.2]).unwrap();
    assert!(allocations() > after);
}
