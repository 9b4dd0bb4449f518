// How detsim diff and detsim bisect show one field difference (cmd_diff.cpp).
#pragma once

#include <string>

#include <detsim/sim/state_diff.hpp>

namespace detsim::cli {

/// {"subsystem", "body", "field", "a", "b"} as one JSON object.
std::string field_json(const FieldDiff& f);
/// Two indented lines on stdout: where and the field with A's value, then B's value.
void print_field(const FieldDiff& f);

}  // namespace detsim::cli
