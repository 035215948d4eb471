//! Arbitrary bytes as a `.xyz` file into `crease::io::read`: the reader of the text point formats
//! (.xyz .txt .csv .pts share one parser), lenient and strict, then what `crease info` and `crease
//! convert` do with the result (`crease_fuzz::read_as`). Finds panics, hangs and huge allocations
//! on hostile files.

#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    crease_fuzz::guarded(|| crease_fuzz::read_as("xyz", data))
});
