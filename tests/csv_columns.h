// The numeric columns of a results CSV file (branch-*.csv, curve_*.csv) by header name, for tests that
// check a run's rows against independent values. Empty and non-numeric cells read as NaN.
#ifndef HYBRIDCONT_TESTS_CSV_COLUMNS_H_
#define HYBRIDCONT_TESTS_CSV_COLUMNS_H_

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

namespace hybridcont {

inline std::map<std::string, std::vector<double>> ReadColumns(const std::filesystem::path& file) {
  std::ifstream in(file);
  std::string line;
  std::getline(in, line);
  std::vector<std::string> header;
  std::stringstream hs(line);
  for (std::string cell; std::getline(hs, cell, ',');) header.push_back(cell);
  std::map<std::string, std::vector<double>> columns;
  while (std::getline(in, line)) {
    std::stringstream ss(line);
    std::size_t i = 0;
    for (std::string cell; i < header.size(); ++i) {
      if (!std::getline(ss, cell, ',')) cell.clear();
      char* end = nullptr;
      const double v = std::strtod(cell.c_str(), &end);
      columns[header[i]].push_back(end != cell.c_str() ? v : std::nan(""));
    }
  }
  return columns;
}

}  // namespace hybridcont

#endif  // HYBRIDCONT_TESTS_CSV_COLUMNS_H_
