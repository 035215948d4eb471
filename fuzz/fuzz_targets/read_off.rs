//! Arbitrary bytes as a `.off` file into `crease::io::read`: the reader of OFF, lenient and strict,
//! then what `crease info` and `crease convert` do with the result (`crease_fuzz::read_as`). Finds
//! panics, hangs and huge allocations on hostile files.

#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    crease_fuzz::guarded(|| crease_fuzz::read_as("off", data))
});
