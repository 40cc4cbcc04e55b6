// Internal to io/inspect: edge topology of a welded soup (edge kinds, edge-connected components,
// closed components and their signed volumes).
#pragma once
#include <cstdint>
#include <vector>

#include "io/inspect/mesh_soup.h"

namespace gibake::mesh {

// Per-triangle component id (0..n-1) and per-component facts.
struct Topology {
  std::vector<uint32_t> component;
  std::vector<uint8_t> closed;
  std::vector<double> volume;  // signed, meaningful for closed components
  std::vector<uint8_t> has_zero_area;
};

// Counts border, non-manifold and inconsistent edges, components and closed components into d.
Topology analyze(const Soup& soup, const std::vector<uint8_t>& zero_area, MeshDiagnostics& d);

}  // namespace gibake::mesh
