// The style sheet and script of gem view's page, as text to embed inline (view_page.hpp).
#pragma once
#include <string_view>

namespace gem {

std::string_view viewStyle();
// Reads its data from <script id="gem-data" type="application/json"> and drives the elements
// that writeViewPage lays out (#view, #series, #bar's controls, #legend, #tip).
std::string_view viewScript();

}  // namespace gem
