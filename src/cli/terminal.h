#pragma once
// What whirl prints reaches the user's terminal through one filter. Messages quote user input
// (a column header, a screw name, a field value from a file someone sent); a hostile one holding
// ESC sequences could otherwise retitle the window, rewrite the screen or, on some terminals,
// reach the clipboard. So every byte written to stdout and stderr passes through TerminalText
// (core/safe_text.h): controls are shown as visible \xNN escapes, valid UTF-8 is unchanged. Also
// when the output goes to a file or a pipe (it is read on a terminal later, with cat or less -R);
// what whirl prints there is text for people, JSON (whose strings nlohmann-json already escapes)
// or a CSV (whirl curve without --out), which changes only where user text holds a control byte.
#include <cstdio>

namespace whirl::cli {

/// Installs the filter on stdio's stdout/stderr and on std::cout/cerr/clog (glibc's fopencookie;
/// stdout/stderr are reassigned, which glibc allows). Call once, before anything is printed;
/// later calls do nothing. The output is flushed at exit (an atexit handler), including a UTF-8
/// sequence cut by a buffer boundary.
void GuardTerminalOutput();

/// stderr without the filter, for the progress bar's carriage return. Whatever user text is
/// written here must pass through TerminalText first.
std::FILE* RawStderr();

}  // namespace whirl::cli
