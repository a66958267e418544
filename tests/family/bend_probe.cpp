// Development driver (not installed, not a test): the practical-equivalence rule of
// family::ChoiceOptions::equivalence_sd on power laws with a real bend, where the GP is right.
// Tables: max elongation = a power law of the five inputs times exp(bend ln^2(raceway radius / 6))
// times exp(noise N(0, 1)) (MakeBentTable, tests/support/power_law_table.h), 20 training rows,
// 30 seeds per (noise, bend); each prediction is scored against the noise-free truth of 400 new
// rows, as the RMSE of ln(prediction / truth) (a relative error). Prints, per (noise, bend), the
// mean of that error over the seeds for the default choice, the choice without the rule
// (equivalence_sd = 0) and the power law alone, and on how many tables the rule set the GP aside.
//   bend_probe        (no arguments; about 2 s)
#include <cmath>
#include <cstdio>

#include "family/family.h"
#include "support/power_law_table.h"

namespace {

using namespace whirl;
using namespace whirl::family;

// RMSE of ln(prediction / truth) of max elongation over `test`.
double RelativeRmse(const Choice& c, const ProcessTable& test) {
  const std::vector<FamilyPrediction> p = PredictChoice(c, test.inputs);
  double s = 0;
  for (std::size_t q = 0; q < p.size(); ++q)
    s += std::pow(std::log(p[q].mean.max_elongation_um / test.targets[q].max_elongation_um), 2);
  return std::sqrt(s / static_cast<double>(p.size()));
}

}  // namespace

int main() {
  ChoiceOptions on, off, power_law;
  off.equivalence_sd = 0;
  power_law.candidates = {ParseCandidate("linear/log")};
  std::printf("noise  bend  default  without_rule  power_law  rule_fired (of 30)\n");
  for (double noise : {0.003, 0.01, 0.04})
    for (double bend : {0.0, 0.15, 0.5, 1.0}) {
      double e_on = 0, e_off = 0, e_pl = 0;
      int fired = 0;
      for (unsigned seed = 1; seed <= 30; ++seed) {
        const ProcessTable train = test::MakeBentTable(20, noise, bend, seed);
        const ProcessTable truth = test::MakeBentTable(400, 0.0, bend, seed + 1000);
        const Choice c = ChooseFamily(train, on);
        fired += !c.notes[0].empty();
        e_on += RelativeRmse(c, truth) / 30;
        e_off += RelativeRmse(ChooseFamily(train, off), truth) / 30;
        e_pl += RelativeRmse(ChooseFamily(train, power_law), truth) / 30;
      }
      std::printf("%5.3f  %4.2f  %7.4f  %12.4f  %9.4f  %d\n", noise, bend, e_on, e_off, e_pl, fired);
    }
  return 0;
}
