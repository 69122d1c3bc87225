// Benchmarks live in bench/*_bench.cc; this file keeps the target non-empty.
