// libFuzzer harness: lead-deviation curves (lead/lead.h ReadLeadDeviation, then the metrics).
// Bad input must be an InputError; any other exception, crash, hang, leak or sanitizer report is a
// bug (tests/fuzz/README.md).
#include "lead/lead.h"
#include "lead/metrics.h"
#include "core/error.h"
#include "fuzz_file.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::filesystem::path path = whirl::fuzz::FuzzFile(data, size, ".csv");
  try {
    const whirl::lead::LeadDeviation lead = whirl::lead::ReadLeadDeviation(path);
    (void)whirl::lead::ComputeLeadMetrics(lead);
  } catch (const whirl::InputError& e) {
  whirl::fuzz::Refused(e);
  }
  return 0;
}
