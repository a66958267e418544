#include "cli/terminal.h"

#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <iostream>
#include <streambuf>
#include <string>
#include <string_view>

#include "core/safe_text.h"

namespace whirl::cli {
namespace {

// One filtered descriptor: what was written but ends in an unfinished UTF-8 sequence waits here.
struct Filter {
  int fd;
  std::string pending;
};

Filter g_stdout_filter{1, {}};
Filter g_stderr_filter{2, {}};
std::FILE* g_raw_stderr = nullptr;

// Bytes at the end of `text` that begin a UTF-8 sequence whose remaining bytes have not come yet.
std::size_t UnfinishedUtf8Tail(std::string_view text) {
  for (std::size_t back = 1; back <= 3 && back <= text.size(); ++back) {
    const auto c = static_cast<unsigned char>(text[text.size() - back]);
    if ((c & 0xC0) == 0x80) continue;  // a continuation byte: its lead lies further back
    const std::size_t need = c >= 0xF0 ? 4 : c >= 0xE0 ? 3 : c >= 0xC2 ? 2 : 1;
    return need > back ? back : 0;
  }
  return 0;
}

void WriteAll(int fd, std::string_view bytes) {
  while (!bytes.empty()) {
    const ssize_t n = ::write(fd, bytes.data(), bytes.size());
    if (n < 0) {
      if (errno == EINTR) continue;
      return;  // the terminal is gone; nothing better to do with the text
    }
    bytes.remove_prefix(static_cast<std::size_t>(n));
  }
}

ssize_t FilterWrite(void* cookie, const char* data, std::size_t size) {
  auto* filter = static_cast<Filter*>(cookie);
  filter->pending.append(data, size);
  const std::size_t ready = filter->pending.size() - UnfinishedUtf8Tail(filter->pending);
  WriteAll(filter->fd, TerminalText(std::string_view(filter->pending).substr(0, ready)));
  filter->pending.erase(0, ready);
  return static_cast<ssize_t>(size);
}

void FlushPending(Filter* filter) {
  if (filter->pending.empty()) return;
  WriteAll(filter->fd, TerminalText(filter->pending));  // an unfinished sequence: shown as \xNN
  filter->pending.clear();
}

// std::cout & co. write into a stdio FILE (so their output and printf's stay in order).
class StdioBuf : public std::streambuf {
 public:
  explicit StdioBuf(std::FILE* file) : file_(file) {}

 protected:
  int overflow(int ch) override {
    if (ch == traits_type::eof()) return traits_type::not_eof(ch);
    return std::fputc(ch, file_) == EOF ? traits_type::eof() : ch;
  }
  std::streamsize xsputn(const char* s, std::streamsize n) override {
    return static_cast<std::streamsize>(std::fwrite(s, 1, static_cast<std::size_t>(n), file_));
  }
  int sync() override { return std::fflush(file_) == 0 ? 0 : -1; }

 private:
  std::FILE* file_;
};

std::FILE* OpenFilter(Filter* filter, int buffering) {
  cookie_io_functions_t io{};
  io.write = FilterWrite;
  std::FILE* file = ::fopencookie(filter, "w", io);
  if (file != nullptr) std::setvbuf(file, nullptr, buffering, buffering == _IONBF ? 0 : BUFSIZ);
  return file;
}

void FinishTerminalOutput() {
  std::cout.flush();
  std::cerr.flush();
  std::fflush(stdout);
  std::fflush(stderr);
  FlushPending(&g_stdout_filter);
  FlushPending(&g_stderr_filter);
}

}  // namespace

void GuardTerminalOutput() {
  if (g_raw_stderr != nullptr) return;
  std::cout.flush();
  std::cerr.flush();
  std::fflush(stdout);
  std::fflush(stderr);
  g_raw_stderr = stderr;
  if (std::FILE* err = OpenFilter(&g_stderr_filter, _IONBF)) {
    // Never destroyed: std::cerr is flushed after static destructors have run.
    auto* err_buf = new StdioBuf(err);
    stderr = err;
    std::cerr.rdbuf(err_buf);
    std::clog.rdbuf(err_buf);
  }
  // Line-buffered on a terminal, fully buffered otherwise, as stdio's own stdout.
  if (std::FILE* out = OpenFilter(&g_stdout_filter, ::isatty(1) != 0 ? _IOLBF : _IOFBF)) {
    auto* out_buf = new StdioBuf(out);  // never destroyed, as err_buf
    stdout = out;
    std::cout.rdbuf(out_buf);
  }
  std::atexit(FinishTerminalOutput);
}

std::FILE* RawStderr() { return g_raw_stderr != nullptr ? g_raw_stderr : stderr; }

}  // namespace whirl::cli
