// Field-level state comparison (state_diff.hpp). Both states are restored into scratch worlds
// (so both are fully validated) and compared through the public body accessors, field by field in
// the order BodyState declares them; contacts pair by pair (World::contacts()), point by point.
#include <detsim/sim/state_diff.hpp>

#include <algorithm>
#include <cstdio>

#include <detsim/fixed/decimal.hpp>

namespace detsim {
namespace {

std::string hex(std::uint64_t v) {
  char text[19];
  std::snprintf(text, sizeof text, "0x%016llx", static_cast<unsigned long long>(v));
  return text;
}

std::string show(Fixed v) {
  return to_string(v) + " (" + hex(static_cast<std::uint64_t>(v.raw())) + ")";
}
std::string show(std::uint64_t v) {
  return std::to_string(v) + " (" + hex(v) + ")";
}
std::string show(bool v) {
  return v ? "true" : "false";
}
std::string show(BodyType t) {
  switch (t) {
    case BodyType::static_body:
      return "static";
    case BodyType::kinematic:
      return "kinematic";
    case BodyType::dynamic:
      return "dynamic";
  }
  return "unknown";
}

class Collector {
 public:
  Collector(StateDiff& out, std::size_t max) : out_(out), max_(max) {}

  void add(const char* subsystem, std::uint32_t body, std::string field, std::string a,
           std::string b) {
    if (out_.fields.size() >= max_) {
      ++out_.omitted;
      return;
    }
    out_.fields.push_back(FieldDiff{subsystem, body, std::move(field), std::move(a), std::move(b)});
  }
  template <class T>
  void field(std::uint32_t body, const std::string& name, const T& a, const T& b,
             const char* subsystem = "bodies") {
    if (!(a == b)) add(subsystem, body, name, show(a), show(b));
  }
  void vec(std::uint32_t body, const std::string& name, Vec3 a, Vec3 b) {
    field(body, name + ".x", a.x, b.x);
    field(body, name + ".y", a.y, b.y);
    field(body, name + ".z", a.z, b.z);
  }
  void quat(std::uint32_t body, const std::string& name, Quat a, Quat b) {
    field(body, name + ".w", a.w, b.w);
    field(body, name + ".x", a.x, b.x);
    field(body, name + ".y", a.y, b.y);
    field(body, name + ".z", a.z, b.z);
  }

 private:
  StateDiff& out_;
  std::size_t max_;
};

void diff_body(Collector& c, const BodyState& a, const BodyState& b) {
  const std::uint32_t id = a.id.value;
  if (a.type != b.type) c.add("bodies", id, "type", show(a.type), show(b.type));
  if (!(a.shape == b.shape)) c.add("bodies", id, "shape", "(differs)", "(differs)");
  c.vec(id, "position", a.position, b.position);
  c.quat(id, "orientation", a.orientation, b.orientation);
  c.vec(id, "linear_velocity", a.linear_velocity, b.linear_velocity);
  c.vec(id, "angular_velocity", a.angular_velocity, b.angular_velocity);
  c.field(id, "mass", a.mass, b.mass);
  c.vec(id, "inertia", a.inertia, b.inertia);
  c.field(id, "friction", a.friction, b.friction);
  c.field(id, "restitution", a.restitution, b.restitution);
  c.field(id, "linear_damping", a.linear_damping, b.linear_damping);
  c.field(id, "angular_damping", a.angular_damping, b.angular_damping);
  c.field(id, "layer", std::uint64_t{a.layer}, std::uint64_t{b.layer});
  c.field(id, "mask", std::uint64_t{a.mask}, std::uint64_t{b.mask});
  c.field(id, "sensor", a.sensor, b.sensor);
  c.field(id, "ccd", a.ccd, b.ccd);
  c.field(id, "user_data", a.user_data, b.user_data);
  c.field(id, "awake", a.awake, b.awake);
  c.field(id, "sleep_time", a.sleep_time, b.sleep_time);
  c.vec(id, "force", a.force, b.force);
  c.vec(id, "torque", a.torque, b.torque);
}

std::string contact_name(const ContactState& c) {
  return "contact[" + std::to_string(c.b.value) + "]";
}

void diff_contact(Collector& c, const ContactState& a, const ContactState& b) {
  const std::uint32_t id = a.a.value;
  const std::string name = contact_name(a);
  c.field(id, name + ".touching", a.touching, b.touching, "contacts");
  c.field(id, name + ".reported", a.reported, b.reported, "contacts");
  c.field(id, name + ".point_count", std::uint64_t{a.point_count}, std::uint64_t{b.point_count},
          "contacts");
  const std::size_t points = std::min(a.point_count, b.point_count);
  for (std::size_t i = 0; i < points; ++i) {
    const std::string p = name + ".point[" + std::to_string(i) + "].";
    const ContactPointState& pa = a.points[i];
    const ContactPointState& pb = b.points[i];
    c.field(id, p + "feature", std::uint64_t{pa.feature}, std::uint64_t{pb.feature}, "contacts");
    c.field(id, p + "normal_impulse", pa.normal_impulse, pb.normal_impulse, "contacts");
    c.field(id, p + "tangent_impulse_1", pa.tangent_impulse_1, pb.tangent_impulse_1, "contacts");
    c.field(id, p + "tangent_impulse_2", pa.tangent_impulse_2, pb.tangent_impulse_2, "contacts");
  }
}

// A merge of both contact lists, ascending (a, b); a pair on one side only is "present".
void diff_contacts(Collector& c, const std::vector<ContactState>& ca,
                   const std::vector<ContactState>& cb) {
  const auto key = [](const ContactState& x) {
    return (std::uint64_t{x.a.value} << 32) | x.b.value;
  };
  std::size_t i = 0;
  std::size_t j = 0;
  while (i < ca.size() || j < cb.size()) {
    if (j == cb.size() || (i < ca.size() && key(ca[i]) < key(cb[j]))) {
      c.add("contacts", ca[i].a.value, contact_name(ca[i]) + ".present", "present", "absent");
      ++i;
    } else if (i == ca.size() || key(cb[j]) < key(ca[i])) {
      c.add("contacts", cb[j].a.value, contact_name(cb[j]) + ".present", "absent", "present");
      ++j;
    } else {
      diff_contact(c, ca[i], cb[j]);
      ++i;
      ++j;
    }
  }
}

}  // namespace

std::vector<std::string> differing_subsystems(const StateHashes& a, const StateHashes& b) {
  std::vector<std::string> out;
  if (a.globals != b.globals) out.emplace_back("globals");
  if (a.rng != b.rng) out.emplace_back("rng");
  if (a.bodies != b.bodies) out.emplace_back("bodies");
  if (a.contacts != b.contacts) out.emplace_back("contacts");
  return out;
}

Expected<StateDiff> diff_states(std::span<const std::uint8_t> a, std::span<const std::uint8_t> b,
                                std::size_t max_fields) {
  World wa;
  World wb;
  if (Status s = wa.restore(a); !s) return Status::error("state A: " + s.message());
  if (Status s = wb.restore(b); !s) return Status::error("state B: " + s.message());
  StateDiff out;
  out.a = wa.hashes();
  out.b = wb.hashes();
  out.frame_a = wa.frame();
  out.frame_b = wb.frame();
  Collector c(out, max_fields);

  // The count is saved with the bodies, not the globals: listed whichever part's hash differs.
  const std::size_t before = out.fields.size() + out.omitted;
  if (wa.body_count() != wb.body_count())
    c.add("globals", 0, "body count", show(std::uint64_t{wa.body_count()}),
          show(std::uint64_t{wb.body_count()}));
  if (out.a.globals != out.b.globals) {
    if (wa.frame() != wb.frame()) c.add("globals", 0, "frame", show(wa.frame()), show(wb.frame()));
    if (!(wa.def() == wb.def())) c.add("globals", 0, "world definition", "(differs)", "(differs)");
    // Otherwise a global without an accessor differs (the next body ID): name the part's hashes.
    if (out.fields.size() + out.omitted == before)
      c.add("globals", 0, "hash", show(out.a.globals), show(out.b.globals));
  }
  const Rng::State& ra = wa.rng().state();
  const Rng::State& rb = wb.rng().state();
  for (std::size_t i = 0; i < ra.size(); ++i)
    if (ra[i] != rb[i])
      c.add("rng", 0, "state[" + std::to_string(i) + "]", show(ra[i]), show(rb[i]));

  // Bodies: a merge of both ascending ID lists.
  const std::size_t before_bodies = out.fields.size() + out.omitted;
  const std::vector<BodyId> ia = wa.body_ids();
  const std::vector<BodyId> ib = wb.body_ids();
  std::size_t i = 0;
  std::size_t j = 0;
  while (i < ia.size() || j < ib.size()) {
    if (j == ib.size() || (i < ia.size() && ia[i].value < ib[j].value)) {
      c.add("bodies", ia[i].value, "present", "present", "absent");
      ++i;
    } else if (i == ia.size() || ib[j].value < ia[i].value) {
      c.add("bodies", ib[j].value, "present", "absent", "present");
      ++j;
    } else {
      diff_body(c, wa.body(ia[i]).value(), wb.body(ib[j]).value());
      ++i;
      ++j;
    }
  }
  // A body's encoding may hold more than BodyState shows: name the part's hashes then.
  if (out.a.bodies != out.b.bodies && out.fields.size() + out.omitted == before_bodies)
    c.add("bodies", 0, "hash", show(out.a.bodies), show(out.b.bodies));
  if (out.a.contacts != out.b.contacts) {
    const std::size_t before_contacts = out.fields.size() + out.omitted;
    diff_contacts(c, wa.contacts(), wb.contacts());
    if (out.fields.size() + out.omitted == before_contacts)
      c.add("contacts", 0, "cache", show(out.a.contacts), show(out.b.contacts));
  }
  return out;
}

}  // namespace detsim
