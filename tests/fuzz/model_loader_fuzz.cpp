// libFuzzer target for the model loader (scripts/fuzz.sh, docs/reliability.md).
//
// Each input is taken as the text of a model file. The loader must either
// reject it with a ModelError or return a ModelSpec; anything else (a crash,
// an ASan/UBSan report, another exception escaping, a hang) is a finding.
// A loaded spec is then
//   * compiled: compile() must either succeed or throw (ModelError, or another
//     std::exception for what it checks numerically), never crash;
//   * written and read back: to_json -> text -> parse_model_spec_text ->
//     to_json must give the same JSON document; a difference abort()s, so the
//     fuzzer keeps the input.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <nlohmann/json.hpp>
#include <string>

#include "io/model_file.hpp"
#include "dynamics/prepare.hpp"
#include "model/errors.hpp"

namespace {

[[noreturn]] void finding(const char* what, const std::string& detail) {
  std::fprintf(stderr, "model_loader_fuzz: %s\n%s\n", what, detail.c_str());
  std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  codyna::ModelSpec spec;
  try {
    spec = codyna::parse_model_spec_text(text, "fuzz");
  } catch (const codyna::ModelError&) {
    return 0;  // a clean rejection
  }
  // Any other exception escapes and libFuzzer reports it (deadly signal).

  try {
    (void)codyna::compile(spec, "fuzz");
  } catch (const codyna::ModelError&) {
  } catch (const std::exception&) {
  }

  // The round trip: what is written reads back to the same document.
  nlohmann::json first;
  std::string written;
  try {
    first = codyna::to_json(spec);
    written = first.dump();
  } catch (const std::exception& e) {
    finding("to_json / dump of a loaded spec threw", e.what());
  }
  nlohmann::json second;
  try {
    second = codyna::to_json(codyna::parse_model_spec_text(written, "fuzz-written"));
  } catch (const std::exception& e) {
    finding("the written model does not load again", std::string(e.what()) + "\nwritten: " + written);
  }
  if (first != second)
    finding("round trip changed the model",
            "written: " + written + "\nread back: " + second.dump() +
                "\ndiff: " + nlohmann::json::diff(first, second).dump());
  return 0;
}
