// One parser per option kind, shared by every command: number lists and vec3s, --sun, on|off,
// --backend with --vulkan-device, the thread count's cap, and CLI11 checks whose messages say what
// was expected (instead of "Could not convert"). Every failure is a BadArguments Status naming
// the option.
#pragma once

#include <CLI/CLI.hpp>
#include <array>
#include <cstdint>
#include <initializer_list>
#include <string>
#include <vector>

#include "bake/run/backend.h"
#include "bake/scene/lights.h"
#include "io/scene.h"
#include "io/status.h"

namespace gibake::cli {

constexpr unsigned kMaxThreads = 1024;  // far beyond any machine; larger values are typos

Status bad_arg(const std::string& option, const std::string& what);

// "a<sep>b<sep>c" -> exactly n finite numbers; false otherwise.
bool parse_numbers(const std::string& text, char sep, size_t n, std::vector<double>& out);
// x,y,z
Status parse_vec3(const std::string& option, const std::string& text, std::array<float, 3>& out);
// Places in metres (eyes, targets, box corners) within kMaxSceneCoordinate of the origin: values
// [first, first + count) of `v`, parsed from `text`.
Status check_places(const std::string& option, const std::vector<double>& v, size_t first, size_t count,
                    const std::string& text);
// A view's 9 numbers eye,target,up (`text` as given): eye and target apart, up neither zero nor
// along the view, so that the view is what was written rather than a guess.
Status check_view_vectors(const std::string& option, const std::vector<double>& v, const std::string& text);
// x,y,z as a place (check_places).
Status parse_place(const std::string& option, const std::string& text, std::array<float, 3>& out);
// dx,dy,dz:lux[:r,g,b], every --sun of a command.
Status parse_sun(const std::string& text, SunLight& sun);
Status parse_suns(const std::vector<std::string>& texts, std::vector<SunLight>& suns);
// on|off
Status parse_on_off(const std::string& option, const std::string& text, bool& out);
// --backend auto|cpu|vulkan with --vulkan-device (which only names a device for vulkan or auto).
Status parse_backend_options(const std::string& backend, const std::string& vulkan_device, BackendSettings& out);

// CLI11 checks with messages in the user's words: a whole number within [lo, hi], a number > 0.
CLI::Validator whole_number(int64_t lo, int64_t hi);
CLI::Validator positive_number();
CLI::Validator non_negative_number();
// Every number option of `command` (CLI11's FLOAT) refuses NaN, infinities and values beyond a
// float's range, which no option means and which comparisons with a range would let through.
// Called once a command's options are all added.
void require_finite_numbers(CLI::App& command);
// Every option that names a file or folder (FILE, DIR, EXR, PART..., SCENE) refuses an empty path.
void require_paths(CLI::App& command);
// Digits only, up to 2^64 - 1 (CLI11 would take "-1" as 2^64 - 1): seeds.
CLI::Validator unsigned_integer();
// An output named as another kind of file than `written` (probes.png for a bake file, scene.gltf
// for an OpenVDB file): refused, since people and tools would open it as that kind (and it may be a
// file kept for what it is). The kind's `own` extensions (the first is the one the refusal
// suggests), unknown ones and none are taken.
Status check_output_kind(const std::string& option, const std::string& path, std::initializer_list<const char*> own,
                         const std::string& written);
// check_output_kind for a bake file: .gibake, .bin.
Status check_bake_file_name(const std::string& option, const std::string& path);

// --threads with the common cap, wording and default, under the help heading `group`.
CLI::Option* add_threads_option(CLI::App* sub, unsigned& threads, const std::string& what_does_not_depend_on_it,
                                const std::string& group = "Options");

}  // namespace gibake::cli
