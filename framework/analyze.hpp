// gem analyze: impact-load statistics of a run folder or a sweep folder (issue 5, item 5; thesis
// 6.2.2.4 to 6.2.2.6). Writes CSV tables and SVG plots into the folder.
#pragma once
#include <string>

namespace gem {

struct AnalyzeOptions {
  std::string dir;  // a run folder (impacts.csv) or a sweep folder (cases/*/impacts.csv)
  bool quiet = false;
};

int runAnalyze(const AnalyzeOptions& options);

}  // namespace gem
