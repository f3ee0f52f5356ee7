// The model file of a chain of `masses` unit masses on unit springs, the first tied to a wall, the last
// bouncing elastically off a stop at x = 0 (models/mass-chain.toml has 12): one phase of 2·masses states.
// For the tests and benchmarks of large phases, at any size.
#ifndef HYBRIDCONT_TESTS_MASS_CHAIN_TEXT_H_
#define HYBRIDCONT_TESTS_MASS_CHAIN_TEXT_H_

#include <string>

namespace hybridcont::test_models {

inline std::string MassChainText(int masses) {
  std::string states, ode, kinetic, potential = "x1^2", reset;
  for (int i = 1; i <= masses; ++i) {
    const std::string x = "x" + std::to_string(i), v = "v" + std::to_string(i);
    const std::string left = i > 1 ? "x" + std::to_string(i - 1) : "0";
    const std::string acc = i < masses ? "k/m*(" + left + " - 2*" + x + " + x" + std::to_string(i + 1) + ")"
                                       : "k/m*(" + left + " - " + x + ")";
    states += (i > 1 ? ", \"" : "\"") + x + "\"";
    ode += (i > 1 ? ", " : "") + x + " = \"" + v + "\", " + v + " = \"" + acc + "\"";
    kinetic += (i > 1 ? " + " : "") + v + "^2";
    if (i > 1) potential += " + (" + x + " - x" + std::to_string(i - 1) + ")^2";
    reset += (i > 1 ? ", " : "") + x + " = \"" + x + "\", " + v + " = \"" + (i < masses ? v : "-" + v) + "\"";
  }
  for (int i = 1; i <= masses; ++i) states += ", \"v" + std::to_string(i) + "\"";
  const std::string last = std::to_string(masses);
  return "hybridcont = 1\nname = \"mass-chain\"\n[parameters]\nm = { value = 1.0 }\nk = { value = 1.0 }\n"
         "[[phases]]\nname = \"free\"\nstates = [" + states + "]\node = { " + ode + " }\nenergy = \"0.5*m*(" +
         kinetic + ") + 0.5*k*(" + potential + ")\"\nevent = \"-x" + last + "\"\nanchor = \"-v" + last +
         "\"\nreset = { " + reset + " }\n[start]\nkind = \"singular\"\n";
}

}  // namespace hybridcont::test_models

#endif  // HYBRIDCONT_TESTS_MASS_CHAIN_TEXT_H_
