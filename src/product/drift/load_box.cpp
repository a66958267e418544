#include "drift/load_box.h"

namespace whirl::drift {

report::Box DriftLoadBox(const std::string& model_kind, const std::string& error_column,
                         const std::vector<std::string>& inputs, const std::string& model_file) {
  using report::Bold;
  using report::Code;
  using report::MakeBlock;
  using report::Text;
  report::Box box;
  box.id = "load";
  box.blocks.push_back(MakeBlock(report::Heading{2, "Load onto the control", ""}));
  const std::string model = model_file.empty() ? "MODEL.json" : model_file;
  box.blocks.push_back(MakeBlock(report::Paragraph{
      {Bold("Files onto the control:"),
       Text(" this command writes no NC program. For your machine, ")},
      report::Tone::kNormal}));
  box.blocks.back().paragraph.spans.push_back(
      Code("whirl drift nc --model " + model +
           " --machine PROFILE.json --nc WHIRL_DRIFT_COMP.SPF --reset-nc "
           "WHIRL_DRIFT_COMP_RESET.SPF --csv WHIRL_DRIFT_COMP_PLC.csv"));
  box.blocks.back().paragraph.spans.push_back(
      Text(" writes the live drift action (static synchronized actions that write SD43900 from "
           "the model every interpolation cycle), its reset program and the PLC table."));
  if (model_kind.rfind("network", 0) == 0)
    box.blocks.push_back(MakeBlock(report::Paragraph{
        {Text("This model is a network: drift nc takes models of kind mlr or dynamic only; fit "
              "one of those (whirl drift fit --kind mlr or dynamic) to compensate on the "
              "control.")},
        report::Tone::kWarn}));
  std::string read;
  for (const auto& i : inputs) read += (read.empty() ? "" : ", ") + i;
  box.blocks.push_back(MakeBlock(report::Paragraph{
      {Bold("What the action reads and writes:"),
       Text(" the model of " + error_column + " (" + model_kind + ") from " +
            (read.empty() ? std::string("the inputs the model names") : read) +
            ", each on an analog input the machine profile maps; it writes SD43900 (and with a "
            "slope model SD43910/SD43920).")}}));
  box.blocks.push_back(MakeBlock(report::Paragraph{
      {Bold("Call:"), Text(" WHIRL_DRIFT_COMP once at power-on (it keeps running; its rises and "
                           "lags count from its start); WHIRL_DRIFT_COMP_RESET stops it and "
                           "restores the setting data found.")}}));
  box.blocks.push_back(MakeBlock(report::Paragraph{
      {Bold("Machine data the programs need:"),
       Text(" drift nc prints them for the profile (MD32750 bit 0 on the axis, MD28250 "
            "synchronized-action elements, MD28254 $AC_PARAM slots, MD10300 analog inputs) in "
            "the program's header lines.")},
      report::Tone::kSmall}));
  return box;
}

}  // namespace whirl::drift
