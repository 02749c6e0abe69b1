// Streaming I/O: Google Benchmarks of chunked writing and reading, plus two modes used by
// scripts/bench_io.sh to show that fitting streams:
//   io_streaming_benchmark --generate <set.h5> <samples> [seed]  writes a set chunk by chunk
//     (3 commands, x in R^2, z in R^2, a 3-component mixture per command), memory ~ one chunk;
//   io_streaming_benchmark --read-all <set.h5>   loads the whole set (the non-streaming path).
// Without these flags it runs the benchmarks (Google Benchmark flags apply).
#include <benchmark/benchmark.h>

#include <cstdio>
#include <cstring>
#include <exception>
#include <filesystem>
#include <random>
#include <string>

#include "io/sample_set_io.h"
#include "io/sample_stream.h"

namespace dgmm {
namespace {

// Header: 3 commands (forward speed, turn), x = (dx, dyaw), z = (pitch, roll).
SampleSet Header() {
  SampleSet h;
  h.command_dim_names = {"speed", "turn"};
  h.commands.resize(3, 2);
  h.commands << 0.5, 0, 0.5, 1, 0, 1;
  h.command_labels = {"0.5,0", "0.5,1", "0,1"};
  h.x.resize(0, 2);
  h.z.resize(0, 2);
  h.x_names = {"dx", "dyaw"};
  h.x_units = {"m", "rad"};
  h.z_names = {"pitch", "roll"};
  h.z_units = {"rad", "rad"};
  h.source = "synthetic";
  h.metadata["generator"] = "io_streaming_benchmark --generate";
  return h;
}

// Fills `chunk` with n samples: command c, component k ~ U{0,1,2}, x and z around centres.
void FillChunk(int n, std::mt19937_64& rng, SampleSet* chunk) {
  std::normal_distribution<double> normal(0.0, 1.0);
  std::uniform_int_distribution<int> pick(0, 2);
  chunk->command.resize(n);
  chunk->x.resize(n, 2);
  chunk->z.resize(n, 2);
  for (int i = 0; i < n; ++i) {
    const int c = pick(rng), k = pick(rng);
    chunk->command[i] = c;
    const double pitch = 0.1 * normal(rng), roll = 0.1 * normal(rng);
    chunk->z(i, 0) = pitch;
    chunk->z(i, 1) = roll;
    chunk->x(i, 0) = 0.2 * (c + 1) + 0.1 * k + 0.5 * pitch + 0.02 * normal(rng);
    chunk->x(i, 1) = 0.3 * (c == 1) - 0.2 * k + 0.5 * roll + 0.05 * normal(rng);
  }
}

void Generate(const std::string& path, long long samples, std::uint64_t seed) {
  SampleSetWriter writer(path, Header());
  std::mt19937_64 rng(seed);
  SampleSet chunk = Header();
  constexpr long long kChunk = 65536;
  for (long long done = 0; done < samples; done += kChunk) {
    FillChunk(static_cast<int>(std::min(kChunk, samples - done)), rng, &chunk);
    writer.Append(chunk);
  }
  writer.Commit();
  std::printf("wrote %lld samples to %s\n", samples, path.c_str());
}

std::string BenchFile(long long samples) {
  static std::string path;
  if (path.empty()) {
    path = (std::filesystem::temp_directory_path() / "dgmm-io-bench.h5").string();
    Generate(path, samples, 1);
  }
  return path;
}

constexpr long long kBenchSamples = 1 << 20;

void BM_WriteChunked(benchmark::State& state) {
  const std::string path = (std::filesystem::temp_directory_path() / "dgmm-io-bench-w.h5");
  std::mt19937_64 rng(2);
  SampleSet chunk = Header();
  FillChunk(65536, rng, &chunk);
  for (auto _ : state) {
    SampleSetWriter writer(path, Header());
    for (long long done = 0; done < kBenchSamples; done += 65536) writer.Append(chunk);
    writer.Commit();
  }
  state.SetItemsProcessed(state.iterations() * kBenchSamples);
  std::filesystem::remove(path);
}
BENCHMARK(BM_WriteChunked)->Unit(benchmark::kMillisecond);

void BM_ReadChunked(benchmark::State& state) {
  const std::string path = BenchFile(kBenchSamples);
  for (auto _ : state) {
    SampleSetReader reader(path, static_cast<int>(state.range(0)));
    SampleSet chunk;
    while (reader.Next(&chunk)) benchmark::DoNotOptimize(chunk.x.data());
  }
  state.SetItemsProcessed(state.iterations() * kBenchSamples);
}
BENCHMARK(BM_ReadChunked)->Arg(4096)->Arg(65536)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace dgmm

int main(int argc, char** argv) {
  try {
    if (argc >= 4 && std::strcmp(argv[1], "--generate") == 0) {
      dgmm::Generate(argv[2], std::stoll(argv[3]), argc >= 5 ? std::stoull(argv[4]) : 1);
      return 0;
    }
    if (argc == 3 && std::strcmp(argv[1], "--read-all") == 0) {
      const dgmm::SampleSet set = dgmm::ReadSampleSet(argv[2]);
      std::printf("read %d samples\n", set.size());
      return 0;
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "io_streaming_benchmark: %s\n", e.what());
    return 1;
  }
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  std::filesystem::remove(std::filesystem::temp_directory_path() / "dgmm-io-bench.h5");
  return 0;
}
