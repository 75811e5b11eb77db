//! Prints the two performance figures the hal issue asks for:
//! `cargo run --release -p fovea-hal --example hal_bench`.

use fovea_hal::{GazeSource, HmdDescription, Playback, SimulatedFove, Trace, TraceHeader};
use std::hint::black_box;
use std::time::Instant;

fn main() {
    let mut sim = SimulatedFove::fove0(1);
    let n = 5_000_000u64;
    let start = Instant::now();
    for _ in 0..n {
        black_box(sim.step());
    }
    let rate = n as f64 / start.elapsed().as_secs_f64();
    println!("simulator: {:.2} M samples/s (target >= 1 M/s)", rate / 1e6);

    // Per-frame query pattern: 90 Hz frames against a 120 Hz simulated tracker.
    let mut sim = SimulatedFove::fove0(2);
    let frames = 1_000_000i64;
    let start = Instant::now();
    for f in 0..frames {
        black_box(sim.sample_at(f * 11_111_111));
    }
    let per = start.elapsed().as_nanos() as f64 / frames as f64;
    println!(
        "simulator sample_at per frame (generates ~1.3 ticks): {per:.0} ns (target < 1000 ns)"
    );

    // Playback query: binary search + interpolation in a one-hour 120 Hz trace.
    let mut src = SimulatedFove::fove0(3);
    let samples: Vec<_> = (0..432_000).map(|_| src.step().sample).collect();
    let mut play = Playback::new(
        Trace {
            header: TraceHeader::new("fove0", 120.0),
            samples,
        },
        HmdDescription::fove0(),
    );
    let queries = 2_000_000i64;
    let start = Instant::now();
    for q in 0..queries {
        black_box(play.sample_at((q * 1_799_999_977) % 3_600_000_000_000));
    }
    let per = start.elapsed().as_nanos() as f64 / queries as f64;
    println!("playback sample_at (1 h trace, random times): {per:.0} ns (target < 1000 ns)");
    let start = Instant::now();
    for q in 0..queries {
        black_box(play.sample_at(q * 1_111_111));
    }
    let per = start.elapsed().as_nanos() as f64 / queries as f64;
    println!("playback sample_at (1 h trace, 900 Hz monotonic frame times): {per:.0} ns (target < 1000 ns)");
}
