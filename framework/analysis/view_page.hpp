// gem view: one self-contained HTML page that plays a run's frames (frames.ice) on a canvas, with
// its time series (timeseries.csv), impacts (impacts.csv) and summary (summary.json) when present.
// Everything is inline (no network): the script, the style and the data, base64 typed arrays.
#pragma once
#include <cstdint>
#include <filesystem>
#include <string>

namespace gem {

// Pages larger than this are thinned (every > 0 overrides): a browser tab holds a few hundred MB.
constexpr std::uint64_t kViewMaxBytes = 300ull << 20;

struct ViewOptions {
  std::string dir;  // the run folder
  std::string out;  // the page; default DIR/view.html
  int every = 0;    // keep every N-th frame (and the last); 0: all, thinned when the page would pass maxBytes
  bool quiet = false;
  std::uint64_t maxBytes = kViewMaxBytes;  // the frames' share of the page (tests lower it)
};

// Writes the page atomically and prints its path (and any thinning) unless quiet; returns 0.
// Throws InputError when DIR is not a folder or holds no frames.ice (naming the folder and the fix),
// or when one of its files is malformed.
int runView(const ViewOptions& options);

}  // namespace gem
