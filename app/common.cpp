#include "common.hpp"

#include <iostream>
#include <stdexcept>

#include "io/model_file.hpp"

namespace codyna::cli {

Model load_model(const std::string& path) {
  const ModelSpec spec = load_model_spec(path);
  return compile(spec, path);
}

int run_guarded(const std::function<void()>& f) {
  try {
    f();
    return 0;
  } catch (const ModelError& e) {
    std::cerr << "codyna: error: " << e.what() << "\n";
    return 1;
  } catch (const std::invalid_argument& e) {
    std::cerr << "codyna: error: " << e.what() << "\n";
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "codyna: error: " << e.what() << "\n";
    return 2;
  }
}

}  // namespace codyna::cli
