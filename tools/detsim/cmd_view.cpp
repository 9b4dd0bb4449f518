// detsim view: one or two records of a match (replays, desync reports) as one self-contained HTML
// page that plays the match in 3D (docs/VIEWER.md). replay/view.hpp re-simulates the records;
// this file packs the frames into the page's data and writes the page around three.js (Debian's
// libjs-three, inlined) and the viewer's own script (view_page.js).
//
// The page's data: a JSON header (records, bodies with their outlines in body space, particle
// groups, camera) and the frames in chunks of view_chunk_frames, each compressed with zlib on its
// own (the page inflates a chunk when it is first shown, with the browser's DecompressionStream),
// so that an hour of play opens as fast as a minute. Inside a chunk every pose is quantised
// (position to 1/512 m, the quaternion as its three smallest components to 1/8191 and which one is
// left out) and stored as each channel's second differences over frames: a body at rest or in
// free flight is a run of zeros that zlib all but removes.
#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <detsim/fixed/math.hpp>
#include <detsim/replay/view.hpp>

#include "commands.hpp"
#include "output.hpp"

#if DETSIM_WITH_ZLIB
#include <zlib.h>
#endif

namespace detsim::cli {

#if DETSIM_WITH_ZLIB

extern const char* const view_page_js;

namespace {

/// Frames per chunk: ten seconds at 60 Hz.
constexpr std::uint32_t view_chunk_frames = 600;
/// A page larger than this is refused before it is written (it would not open in a browser).
constexpr std::size_t view_max_page_bytes = std::size_t{1} << 30;

class VarintWriter {
 public:
  void u(std::uint64_t v) {
    while (v >= 0x80) {
      bytes_.push_back(static_cast<std::uint8_t>(v | 0x80));
      v >>= 7;
    }
    bytes_.push_back(static_cast<std::uint8_t>(v));
  }
  /// Zigzag: 0, -1, 1, -2, ... as 0, 1, 2, 3, ...
  void s(std::int64_t v) {
    u((static_cast<std::uint64_t>(v) << 1) ^ static_cast<std::uint64_t>(v >> 63));
  }
  void u64le(std::uint64_t v) {
    for (int i = 0; i < 8; ++i)
      bytes_.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
  }
  void byte(std::uint8_t b) { bytes_.push_back(b); }
  void append(std::span<const std::uint8_t> b) { bytes_.insert(bytes_.end(), b.begin(), b.end()); }
  /// Each value as its second difference from the two before it (zero before the first).
  void second_differences(const std::vector<std::int64_t>& values, std::size_t first,
                          std::size_t stride, std::size_t count) {
    std::int64_t prev = 0;
    std::int64_t prev2 = 0;
    for (std::size_t i = 0; i < count; ++i) {
      const std::int64_t v = values[first + i * stride];
      s(v - 2 * prev + prev2);
      prev2 = prev;
      prev = v;
    }
  }
  [[nodiscard]] std::vector<std::uint8_t>& bytes() { return bytes_; }

 private:
  std::vector<std::uint8_t> bytes_;
};

/// Metres to 1/512 m (2 mm), rounded: the raw Q32.32 value shifted (exact, the same everywhere).
constexpr int view_length_shift = 23;
std::int64_t quantise_length(Fixed v) {
  return (v.raw() + (std::int64_t{1} << (view_length_shift - 1))) >> view_length_shift;
}
/// A unit quaternion component to 1/8191 (a turn of 0.014 degrees at most).
constexpr std::int64_t view_unit_scale = 8191;
std::int64_t quantise_unit(Fixed v) {
  return (v.raw() * view_unit_scale + (std::int64_t{1} << 31)) >> 32;
}

std::string number(Fixed v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.5g", v.to_double());
  return buf;
}
std::string vec_json(Vec3 v) {
  return "[" + number(v.x) + "," + number(v.y) + "," + number(v.z) + "]";
}

std::string outline_json(const ShapeOutline& o) {
  std::string points;
  for (const Vec3& p : o.points)
    points += (points.empty() ? "" : ",") + vec_json(p);
  std::string triangles;
  for (const auto& t : o.triangles)
    for (const Vec3& p : t)
      triangles +=
          (triangles.empty() ? "" : ",") + number(p.x) + "," + number(p.y) + "," + number(p.z);
  std::string parts;
  for (const ShapeOutline& part : o.parts)
    parts += (parts.empty() ? "" : ",") + outline_json(part);
  Json j;
  j.raw("points", "[" + points + "]").raw("radius", number(o.radius));
  if (o.half_space) j.boolean("half_space", true).raw("normal", vec_json(o.normal));
  if (!o.triangles.empty()) j.raw("triangles", "[" + triangles + "]");
  if (!o.parts.empty()) j.raw("parts", "[" + parts + "]");
  return j.text();
}

const char* type_name(BodyType t) {
  switch (t) {
    case BodyType::static_body:
      return "static";
    case BodyType::kinematic:
      return "kinematic";
    case BodyType::dynamic:
      return "dynamic";
  }
  return "dynamic";
}

std::string base64(const std::vector<std::uint8_t>& in) {
  static constexpr char digits[] =
      "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((in.size() + 2) / 3 * 4);
  for (std::size_t i = 0; i < in.size(); i += 3) {
    const std::uint32_t b0 = in[i];
    const std::uint32_t b1 = i + 1 < in.size() ? in[i + 1] : 0;
    const std::uint32_t b2 = i + 2 < in.size() ? in[i + 2] : 0;
    const std::uint32_t w = b0 << 16 | b1 << 8 | b2;
    out += digits[w >> 18];
    out += digits[(w >> 12) & 63];
    out += i + 1 < in.size() ? digits[(w >> 6) & 63] : '=';
    out += i + 2 < in.size() ? digits[w & 63] : '=';
  }
  return out;
}

/// `s` safe inside a <script> element: no "</" that could close it (JSON and JavaScript read
/// "<\/" as "</").
std::string script_safe(std::string s) {
  for (std::size_t at = s.find("</"); at != std::string::npos; at = s.find("</", at + 3))
    s.replace(at, 2, "<\\/");
  return s;
}

std::string html_escape(std::string_view s) {
  std::string out;
  for (const char c : s) {
    switch (c) {
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '&':
        out += "&amp;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

/// The frames of one chunk, gathered before they are packed.
struct Segment {
  std::uint32_t index = 0;  ///< into the page's body (or group) table
  std::uint32_t start = 0;  ///< frame within the chunk
  std::uint32_t count = 0;
  std::uint32_t width = 7;            ///< values per frame
  std::vector<std::int64_t> values;   ///< count * width, frame after frame
  std::vector<std::uint8_t> differs;  ///< bodies: one flag per frame
};

/// The page's data, built frame by frame (replay::ViewSink).
class PageData final : public replay::ViewSink {
 public:
  Status begin(const replay::ViewInfo& info) override {
    info_ = info;
    sides_ = info.records.size();
    unit_ = std::size_t{info.fingerprint.players} * info.fingerprint.input_size;
    open_bodies_.assign(sides_, {});
    open_groups_.assign(sides_, {});
    closed_.assign(sides_, {});
    closed_groups_.assign(sides_, {});
    left_out_.assign(sides_, {});
    prev_inputs_.assign(unit_ + 1, 0);
    return Status::success();
  }

  Status frame(const replay::ViewFrame& f) override {
    if (frames_in_chunk_ == 0) {
      head_ = VarintWriter();
      inputs_.clear();
      std::fill(prev_inputs_.begin(), prev_inputs_.end(), std::uint8_t{0});
    }
    const auto i = frames_in_chunk_;
    // Inputs (the disconnected bits, then every player's bytes), each byte XOR the same byte of
    // the frame before: a held input is zeros.
    std::vector<std::uint8_t> in(unit_ + 1, 0);
    in[0] = f.gone;
    std::copy(f.inputs.begin(), f.inputs.end(), in.begin() + 1);
    for (std::size_t k = 0; k < in.size(); ++k) {
      inputs_.push_back(in[k] ^ prev_inputs_[k]);
      prev_inputs_[k] = in[k];
    }
    for (std::size_t s = 0; s < sides_; ++s) {
      const replay::ViewSide& side = f.sides[s];
      // Hash, then flags: bit 0 the record's own state, bit 1 the record's hash differs from it.
      head_.u64le(side.hash);
      const bool differs = side.recorded_hash && *side.recorded_hash != side.hash;
      head_.byte(static_cast<std::uint8_t>((side.stored ? 1 : 0) | (differs ? 2 : 0)));
      if (differs) head_.u64le(*side.recorded_hash);
      for (const replay::ViewBody& b : side.new_bodies)
        add_body(b);
      for (const replay::ViewPose& p : side.bodies)
        add_pose(s, i, p);
      for (const replay::ViewParticles& g : side.particles)
        add_particles(s, i, g);
      if (f.frame == info_.first_frame) extend_bounds(side);
    }
    if (++frames_in_chunk_ == view_chunk_frames) return flush();
    return Status::success();
  }

  Status finish() { return frames_in_chunk_ == 0 ? Status::success() : flush(); }

  [[nodiscard]] const std::vector<std::string>& chunks() const { return chunks_; }
  [[nodiscard]] std::size_t body_count() const { return bodies_json_.size(); }
  [[nodiscard]] std::uint64_t raw_bytes() const { return raw_bytes_; }

  /// The page's JSON header.
  [[nodiscard]] std::string meta() const {
    std::vector<std::string> records;
    for (const replay::ViewRecordInfo& r : info_.records)
      records.push_back(
          Json().str("path", r.path).str("kind", r.kind).num("frames", r.frames).text());
    std::vector<std::string> notes;
    for (const std::string& n : info_.notes)
      notes.push_back(Json::quote(n));
    std::vector<std::string> groups;
    for (const auto& [id, radius] : groups_json_)
      groups.push_back(Json().num("id", id).raw("radius", radius).text());
    const replay::Fingerprint& fp = info_.fingerprint;
    Vec3 centre{};
    Fixed radius = Fixed::from_int(10);
    if (have_bounds_) {
      centre = (lo_ + hi_) * Fixed::half();
      radius = length(hi_ - lo_) * Fixed::half() + Fixed::from_int(1);
    }
    Json j;
    j.str("format", "detsim-view")
        .num("version", 1)
        .raw("records", Json::array(records))
        .str("scenario", fp.scenario)
        .num("seed", fp.params.seed)
        .num("players", fp.players)
        .num("input_size", fp.input_size)
        .boolean("player_inputs", info_.player_inputs)
        .raw("dt", number(fp.dt))
        .num("first", info_.first_frame)
        .num("last", info_.last_frame)
        .num("chunk_frames", view_chunk_frames)
        .num("length_scale", std::int64_t{1} << (32 - view_length_shift))
        .num("unit_scale", view_unit_scale)
        .str("outcome", info_.outcome)
        .frame("first_divergent_frame", info_.first_divergent_frame)
        .raw("notes", Json::array(notes))
        .raw("camera", Json().raw("target", vec_json(centre)).raw("radius", number(radius)).text())
        .raw("bodies", Json::array(bodies_json_))
        .raw("groups", Json::array(groups));
    return j.text();
  }

 private:
  void add_body(const replay::ViewBody& b) {
    if (body_index_.count(b.id) != 0) return;
    body_index_[b.id] = static_cast<std::uint32_t>(bodies_json_.size());
    half_spaces_[b.id] = b.outline.half_space;
    bodies_json_.push_back(Json()
                               .num("id", b.id)
                               .str("type", type_name(b.type))
                               .raw("outline", outline_json(b.outline))
                               .text());
  }

  /// A pose as x, y, z and the quaternion's "smallest three": the component that is left out,
  /// made positive, is the viewer's to recompute; it is kept from frame to frame while it stays
  /// at least 1/2 (so that its recomputation stays exact to the quantisation), else the largest.
  void add_pose(std::size_t side, std::uint32_t i, const replay::ViewPose& p) {
    const std::uint32_t index = body_index_.at(p.id);
    std::int64_t q[4] = {quantise_unit(p.orientation.x), quantise_unit(p.orientation.y),
                         quantise_unit(p.orientation.z), quantise_unit(p.orientation.w)};
    const auto magnitude = [&](int k) { return q[k] < 0 ? -q[k] : q[k]; };
    auto [kept, fresh] = left_out_[side].try_emplace(index, 3);
    int m = kept->second;
    if (fresh || 2 * magnitude(m) < view_unit_scale) {
      m = 0;
      for (int k = 1; k < 4; ++k)
        if (magnitude(k) > magnitude(m)) m = k;
      kept->second = m;
    }
    if (q[m] < 0)
      for (std::int64_t& c : q)
        c = -c;
    Segment& seg = open(open_bodies_[side], closed_[side], index, i, 7);
    seg.values.push_back(quantise_length(p.position.x));
    seg.values.push_back(quantise_length(p.position.y));
    seg.values.push_back(quantise_length(p.position.z));
    for (int k = 0; k < 4; ++k)
      if (k != m) seg.values.push_back(q[k]);
    seg.values.push_back(m);
    seg.differs.push_back(p.differs ? 1 : 0);
  }

  void add_particles(std::size_t side, std::uint32_t i, const replay::ViewParticles& g) {
    auto [it, fresh] =
        group_index_.try_emplace(g.group, static_cast<std::uint32_t>(groups_json_.size()));
    if (fresh) groups_json_.emplace_back(g.group, number(g.radius));
    const auto width = static_cast<std::uint32_t>(3 * g.positions.size());
    Segment& seg = open(open_groups_[side], closed_groups_[side], it->second, i, width);
    for (const Vec3& p : g.positions) {
      seg.values.push_back(quantise_length(p.x));
      seg.values.push_back(quantise_length(p.y));
      seg.values.push_back(quantise_length(p.z));
    }
  }

  /// The open segment of `index` that frame i continues, or a new one.
  static Segment& open(std::map<std::uint32_t, Segment>& open_segments,
                       std::vector<Segment>& closed, std::uint32_t index, std::uint32_t i,
                       std::uint32_t width) {
    auto it = open_segments.find(index);
    if (it != open_segments.end() &&
        (it->second.start + it->second.count != i || it->second.width != width)) {
      closed.push_back(std::move(it->second));
      open_segments.erase(it);
      it = open_segments.end();
    }
    if (it == open_segments.end()) {
      Segment s;
      s.index = index;
      s.start = i;
      s.width = width;
      it = open_segments.emplace(index, std::move(s)).first;
    }
    ++it->second.count;
    return it->second;
  }

  void extend_bounds(const replay::ViewSide& side) {
    const auto add = [&](Vec3 p) {
      if (!have_bounds_) {
        lo_ = hi_ = p;
        have_bounds_ = true;
        return;
      }
      lo_ = {min(lo_.x, p.x), min(lo_.y, p.y), min(lo_.z, p.z)};
      hi_ = {max(hi_.x, p.x), max(hi_.y, p.y), max(hi_.z, p.z)};
    };
    for (const replay::ViewPose& p : side.bodies) {
      // Planes (half-spaces) are infinite: they do not frame the scene.
      const auto it = half_spaces_.find(p.id);
      if (it == half_spaces_.end() || !it->second) add(p.position);
    }
    for (const replay::ViewParticles& g : side.particles)
      for (const Vec3& p : g.positions)
        add(p);
  }

  static void write_segments(VarintWriter& w, std::vector<Segment>& segments, bool bodies) {
    std::sort(segments.begin(), segments.end(), [](const Segment& a, const Segment& b) {
      return a.index != b.index ? a.index < b.index : a.start < b.start;
    });
    w.u(segments.size());
    for (const Segment& s : segments) {
      w.u(s.index);
      w.u(s.start);
      w.u(s.count);
      if (!bodies) w.u(s.width / 3);
      for (std::uint32_t c = 0; c < s.width; ++c)
        w.second_differences(s.values, c, s.width, s.count);
      if (!bodies) continue;
      // Where the body differs between the sides: runs of (first frame, length).
      std::vector<std::pair<std::uint32_t, std::uint32_t>> runs;
      for (std::uint32_t k = 0; k < s.count; ++k) {
        if (s.differs[k] == 0) continue;
        if (!runs.empty() && runs.back().first + runs.back().second == k) {
          ++runs.back().second;
        } else {
          runs.emplace_back(k, 1);
        }
      }
      w.u(runs.size());
      for (const auto& [first, length] : runs) {
        w.u(first);
        w.u(length);
      }
    }
  }

  Status flush() {
    VarintWriter w;
    w.u(frames_in_chunk_);
    w.append(head_.bytes());
    w.append(inputs_);
    for (std::size_t s = 0; s < sides_; ++s) {
      std::vector<Segment> bodies = std::move(closed_[s]);
      for (auto& [index, seg] : open_bodies_[s])
        bodies.push_back(std::move(seg));
      write_segments(w, bodies, true);
      std::vector<Segment> groups = std::move(closed_groups_[s]);
      for (auto& [index, seg] : open_groups_[s])
        groups.push_back(std::move(seg));
      write_segments(w, groups, false);
      closed_[s].clear();
      closed_groups_[s].clear();
      open_bodies_[s].clear();
      open_groups_[s].clear();
    }
    frames_in_chunk_ = 0;
    raw_bytes_ += w.bytes().size();
    uLongf size = compressBound(static_cast<uLong>(w.bytes().size()));
    std::vector<std::uint8_t> packed(size);
    if (compress2(packed.data(), &size, w.bytes().data(), static_cast<uLong>(w.bytes().size()),
                  Z_BEST_COMPRESSION) != Z_OK)
      return Status::error("zlib could not compress a chunk of the page");
    packed.resize(size);
    chunks_.push_back(base64(packed));
    return Status::success();
  }

  replay::ViewInfo info_;
  std::size_t sides_ = 0;
  std::size_t unit_ = 0;
  std::uint32_t frames_in_chunk_ = 0;
  VarintWriter head_;
  std::vector<std::uint8_t> inputs_;
  std::vector<std::uint8_t> prev_inputs_;
  std::vector<std::map<std::uint32_t, Segment>> open_bodies_;
  std::vector<std::map<std::uint32_t, Segment>> open_groups_;
  std::vector<std::vector<Segment>> closed_;
  std::vector<std::vector<Segment>> closed_groups_;
  std::vector<std::map<std::uint32_t, int>> left_out_;  ///< per side and body: add_pose's m
  std::map<std::uint32_t, std::uint32_t> body_index_;
  std::vector<std::string> bodies_json_;
  std::map<std::uint32_t, bool> half_spaces_;
  std::map<std::uint32_t, std::uint32_t> group_index_;
  std::vector<std::pair<std::uint32_t, std::string>> groups_json_;
  std::vector<std::string> chunks_;
  std::uint64_t raw_bytes_ = 0;
  bool have_bounds_ = false;
  Vec3 lo_{};
  Vec3 hi_{};
};

bool read_text(const std::string& path, std::string& out) {
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> in(std::fopen(path.c_str(), "rb"), &std::fclose);
  if (!in) return false;
  char buf[65536];
  std::size_t n = 0;
  while ((n = std::fread(buf, 1, sizeof buf, in.get())) > 0)
    out.append(buf, n);
  return std::ferror(in.get()) == 0;
}

}  // namespace

int view_command(const ViewArgs& args) {
  const auto start = std::chrono::steady_clock::now();
  std::vector<std::string> files{args.record};
  if (!args.other.empty()) files.push_back(args.other);
  // three.js and the two helpers the viewer uses, as Debian's libjs-three installs them.
  static constexpr const char* three_files[] = {"three.min.js", "examples/js/math/ConvexHull.js",
                                                "examples/js/geometries/ConvexGeometry.js",
                                                "examples/js/controls/OrbitControls.js"};
  std::string three;
  for (const char* f : three_files) {
    const std::string path = args.three + "/" + f;
    std::string text;
    if (!read_text(path, text))
      return usage_error("view", "cannot read " + path +
                                     " (three.js: on Debian, apt-get install libjs-three; or give "
                                     "its directory with --three DIR)");
    three += "<script>" + script_safe(std::move(text)) + "</script>\n";
  }

  /// Packs each frame, with a progress bar.
  class Sink final : public replay::ViewSink {
   public:
    explicit Sink(PageData& data) : data_(data) {}
    Status begin(const replay::ViewInfo& info) override {
      info_ = info;
      progress_ = std::make_unique<Progress>("view");
      return data_.begin(info);
    }
    Status frame(const replay::ViewFrame& f) override {
      if (progress_)
        progress_->update(f.frame - info_.first_frame, info_.last_frame - info_.first_frame + 1);
      return data_.frame(f);
    }
    const replay::ViewInfo& info() const { return info_; }

   private:
    PageData& data_;
    replay::ViewInfo info_;
    std::unique_ptr<Progress> progress_;
  };

  PageData data;
  Sink sink(data);
  replay::ViewOptions options;
  options.first = args.from;
  options.last = args.to;
  if (Status s = replay::view_records(files, options, sink); !s)
    return usage_error("view", s.message());
  if (Status s = data.finish(); !s) return usage_error("view", s.message());

  std::string title = "detsim view: " + files.front();
  if (files.size() == 2) title += " and " + files[1];
  std::string page;
  page += "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\n<title>" +
          html_escape(title) + "</title>\n";
  page += "<meta name=\"generator\" content=\"detsim view\">\n";
  page += "</head><body>\n<script type=\"application/json\" id=\"detsim-meta\">" +
          script_safe(data.meta()) + "</script>\n";
  page += "<script type=\"text/plain\" id=\"detsim-chunks\">\n";
  for (const std::string& c : data.chunks()) {
    page += c;
    page += '\n';
  }
  page += "</script>\n" + three + "<script>" + script_safe(view_page_js) +
          "</script>\n</body></html>\n";
  if (page.size() > view_max_page_bytes)
    return usage_error("view", "the page would be " + std::to_string(page.size() >> 20) +
                                   " MiB: show fewer frames (--from, --to)");

  std::string out = args.out;
  if (out.empty()) {
    out = files.front();
    const auto dot = out.find_last_of('.');
    const auto slash = out.find_last_of('/');
    if (dot != std::string::npos && (slash == std::string::npos || dot > slash)) out.resize(dot);
    out += ".html";
  }
  if (!write_file(out, std::vector<std::uint8_t>(page.begin(), page.end())))
    return usage_error("view", "cannot write " + out);
  const double seconds = seconds_since(start);
  const replay::ViewInfo& info = sink.info();
  const std::uint64_t frames = info.last_frame - info.first_frame + 1;
  if (args.json) {
    Json()
        .str("page", out)
        .num("bytes", page.size())
        .num("frames", frames)
        .num("first", info.first_frame)
        .num("last", info.last_frame)
        .num("bodies", data.body_count())
        .num("chunks", data.chunks().size())
        .num("data_bytes_raw", data.raw_bytes())
        .str("outcome", info.outcome)
        .frame("first_divergent_frame", info.first_divergent_frame)
        .real("seconds", seconds)
        .print();
  } else {
    std::printf("wrote %s: %llu frames (%llu to %llu) of %s, %zu bodies, %.1f MB, in %.1f s\n",
                out.c_str(), static_cast<unsigned long long>(frames),
                static_cast<unsigned long long>(info.first_frame),
                static_cast<unsigned long long>(info.last_frame), info.fingerprint.scenario.c_str(),
                data.body_count(), static_cast<double>(page.size()) / 1e6, seconds);
    if (info.first_divergent_frame)
      std::printf(
          "the records diverge at frame %llu (%s): differing bodies are drawn red, side B "
          "as an orange ghost\n",
          static_cast<unsigned long long>(*info.first_divergent_frame), info.outcome.c_str());
    for (const std::string& n : info.notes)
      std::printf("note: %s\n", n.c_str());
  }
  return exit_ok;
}

#else

int view_command(const ViewArgs&) {
  return usage_error("view",
                     "this build has no zlib (DETSIM_WITH_ZLIB=OFF): it cannot write pages");
}

#endif

}  // namespace detsim::cli
