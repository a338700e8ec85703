// SPDX-License-Identifier: MIT
#include "llsf/sim/extension.h"

#include <utility>

namespace llsf::sim {

PreparedGame prepare_game(GameConfig config) {
  config.validate();
  PreparedGame p;
  // The variants in the order of GameConfig::extensions.
  for (const auto& factory : config.extensions) p.extensions.push_back(factory->make());
  // Each draws from its own named streams of the seed, so the order of setup() changes no draw.
  const core::Rng rng(config.seed);
  for (const auto& e : p.extensions) e->setup(config, rng);
  p.config = std::move(config);
  return p;
}

}  // namespace llsf::sim
