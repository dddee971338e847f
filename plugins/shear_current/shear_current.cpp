// shear_current: parameters from [events.shear_current], registration, and the plugin's export.
#include "shear_current.hpp"

#include "framework/api/plugin_api.hpp"
#include "framework/api/registry.hpp"
#include "framework/api/table_reader.hpp"

GEM_PLUGIN("shear_current", "1.0.0")

namespace gem {

static ShearCurrent::Params parseShearCurrent(EventConfig& config) {
  TableReader& t = config.params;
  ShearCurrent::Params p{};
  p.u0 = t.getReal("u0", Real(0.2));
  p.shear = t.getReal("shear", Real(0.01));
  p.yRef = t.getReal("y_ref", 0);
  p.rhoWater = t.getPositive("rho_water", kRhoWater);
  p.coefficient = t.getNonNegative("coefficient", Real(5.5e-3));
  return p;
}

// Off unless the scenario gives [events.shear_current]: loading a plugin changes nothing by itself.
GEM_REGISTER_SOLO_EVENT(ShearCurrent, "shear_current",
                        "current U(y) = u0 + shear (y - y_ref) along x, bulk stress rho_w C_w |U - v| (U - v)", false, parseShearCurrent);

}  // namespace gem
