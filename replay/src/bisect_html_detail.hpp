// Internal to bisect_html (bisect.hpp): what the page (bisect_html.cpp) and its scene plot
// (bisect_html_scene.cpp) share.
#pragma once

#include <string>
#include <string_view>

#include <detsim/replay/bisect.hpp>

namespace detsim::replay::html_detail {

/// `text` with & < > " ' as HTML character references: safe in element text and quoted attributes.
std::string escape(std::string_view text);

/// Appends the "Scene" section: both sides' bodies at diff_frame, top-down (x right, z down), in
/// one view fitted to both. Nothing when both scenes are empty.
void scene_section(std::string& out, const BisectResult& r);

}  // namespace detsim::replay::html_detail
