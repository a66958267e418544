// CsvReader (core/csv.h) on a machine log read from a file, as `whirl drift` streams its runs: a
// run file of 8 columns (time and seven sensors) and 200,000 rows (about 11 MB), read row by row.
// Arg 0: plain names and cells; 1: the names quoted (a spreadsheet's "quote all text cells"
// export); 2: every cell quoted too (each record through the quoted path). Bytes/s per file.
#include <benchmark/benchmark.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "core/csv.h"

namespace {

constexpr int kRows = 200000;
constexpr int kColumns = 8;

std::string Cell(const std::string& text, bool quoted) {
  return quoted ? "\"" + text + "\"" : text;
}

// The log's text: time_min, then t1_C..t7_C with values like a logger's (two decimals).
std::string LogText(bool quote_names, bool quote_cells) {
  std::string text = "# a machine log for bench_csv\n" + Cell("time_min", quote_names);
  for (int c = 1; c < kColumns; ++c) text += "," + Cell("t" + std::to_string(c) + "_C", quote_names);
  text += "\n";
  for (int r = 0; r < kRows; ++r) {
    text += Cell(whirl::FormatNumber(0.5 * r), quote_cells);
    for (int c = 1; c < kColumns; ++c)
      text += "," + Cell(whirl::FormatNumber(20 + 0.01 * ((r * 7 + c * 13) % 1000)), quote_cells);
    text += "\n";
  }
  return text;
}

// The temporary files, removed when the process ends.
struct LogFiles {
  std::filesystem::path path[3];
  ~LogFiles() {
    for (const auto& p : path)
      if (!p.empty()) std::filesystem::remove(p);
  }
};

// The file of one kind, written once per process.
std::filesystem::path LogFile(int kind) {
  static LogFiles files;
  auto& path = files.path[kind];
  if (path.empty()) {
    path = std::filesystem::temp_directory_path() /
           ("whirl_bench_csv_" + std::to_string(kind) + ".csv");
    std::ofstream(path, std::ios::binary | std::ios::trunc) << LogText(kind >= 1, kind == 2);
  }
  return path;
}

void BM_CsvReaderLog(benchmark::State& state) {
  const auto path = LogFile(static_cast<int>(state.range(0)));
  double row[kColumns];
  int line = 0;
  for (auto _ : state) {
    whirl::CsvReader reader(path);
    long long n = 0;
    while (reader.Next(row, &line)) ++n;
    if (n != kRows) state.SkipWithError("wrong row count");
    benchmark::DoNotOptimize(row[kColumns - 1]);
  }
  state.SetBytesProcessed(state.iterations() *
                          static_cast<long long>(std::filesystem::file_size(path)));
}
BENCHMARK(BM_CsvReaderLog)->Arg(0)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
