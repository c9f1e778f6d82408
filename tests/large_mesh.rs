//! An error in a large OBJ file costs what its one shown line costs: the file is not copied or
//! converted to text as a whole (it may be 512 MiB). A counting allocator measures what the
//! loading thread allocates.

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

/// The system allocator, counting the bytes each thread allocates.
struct Counting;

thread_local! {
    static ALLOCATED: Cell<usize> = const { Cell::new(0) };
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let _ = ALLOCATED.try_with(|a| a.set(a.get() + layout.size()));
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

#[test]
fn an_error_in_a_large_mesh_converts_only_its_line() {
    // 32 MiB: a bad first line, then comments, and one byte that is not UTF-8 at the end (so a
    // conversion of the whole file would have to copy it).
    const SIZE: usize = 32 << 20;
    let mut bytes = b"v 0 x 0\n".to_vec();
    bytes.resize(SIZE - 1, b'#');
    bytes.push(0xFF);
    let mesh = Cell::new(Some(bytes));
    let read_mesh = |_: &str| Ok(("big.obj".to_string(), mesh.take().unwrap_or_default()));
    let scene = "[[light]]\nposition = [0, 0, 0]\npower = 1\n[material.m]\ncolour = [1, 1, 1]\n\
                 [[object]]\nkind = \"obj\"\nmaterial = \"m\"\npath = \"big.obj\"\n";
    let before = ALLOCATED.with(Cell::get);
    let err = raytty::scene::file::parse(scene, "s.toml", "s", &read_mesh).unwrap_err();
    let allocated = ALLOCATED.with(Cell::get) - before;
    assert_eq!((err.file.as_str(), err.line, err.column), ("big.obj", 1, 5));
    assert_eq!(err.excerpt, "v 0 x 0");
    assert!(
        allocated < 1 << 20,
        "{allocated} bytes allocated to report an error in a {SIZE}-byte mesh"
    );
}
