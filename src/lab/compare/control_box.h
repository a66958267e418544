#pragma once
// The "load onto the control" box that opens the workpiece and the machine report, rendered from
// the product's data (plan/load.h ControlLoad: the plan's setting data, the files, the machine
// data the programs need, each once, the call order and what to run after an abort). Every text
// reaches the page through HtmlEscape.
#include <string>
#include <vector>

#include "plan/load.h"

namespace whirl::compare {

/// The box (a <section class='control'>) for one or more screws.
std::string ControlBoxHtml(const std::vector<plan::ControlLoad>& loads);

}  // namespace whirl::compare
