// A post-bake filter over neighbouring probes that averages their independent Monte Carlo noise
// away where a grid is dense, and keeps what is real: light that changes across a wall (visibility
// from the bake's own depth moments, the test the sampler applies) and a change larger than the
// probes' combined standard error (the bake's per-probe noise estimate, DdgiProbeStats).
//
// It reads only the result (SH, irradiance atlas, depth atlas, states, stats, offsets), so the one-go
// bake (either backend, on the host after the results return) and the shard merge run the same code
// on the same values: the same bytes whatever the shard or thread count. Depth moments, states and
// stats are left as the rays made them.
#pragma once
#include <cstdint>
#include <string>

#include "io/results/ddgi_result.h"

namespace gibake {

struct ProbeFilterSettings {
  bool enabled = false;  // the CLI's draft level: on (bake/ddgi/quality.h)
  // Width of the noise test: a neighbour whose irradiance differs from the probe's by D counts with
  // exp(-D^2 / (k S^2)), S^2 the expected D^2 under noise alone (probe_filter.cpp).
  float noise_k = 4.f;
};

struct ProbeFilterReport {
  bool ran = false;
  int32_t smoothed = 0;            // probes that took some weight from a neighbour
  int32_t lit = 0;                 // probes not inactive (the filter's candidates)
  double mean_neighbour_weight = 0.0;  // over the lit probes: the share of the result from neighbours
  double mean_error_before = 0.0, mean_error_after = 0.0;  // relative standard error, lit probes
};

// Replaces every lit probe's SH and irradiance tile by the weighted mean over itself and its lit,
// mutually visible grid neighbours (probe_filter.cpp states the weights). Deterministic.
void filter_probes(DdgiResult& result, const ProbeFilterSettings& settings, ProbeFilterReport& report);

// "probe filter: ..." for the bake summary.
std::string probe_filter_summary(const ProbeFilterReport& report);

}  // namespace gibake
