// OFF and PLY polygon-soup readers; contract and reasons in surface_soup.hpp.
#include "surface_soup.hpp"

#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <map>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace spinesim::mesh::detail {
namespace {

[[noreturn]] void refuse(const std::string& why) { throw std::invalid_argument(why); }

/// A finite decimal number filling the whole token.
bool parse_real(const std::string& token, double& value) {
  if (token.empty()) return false;
  errno = 0;
  char* end = nullptr;
  value = std::strtod(token.c_str(), &end);
  return end == token.c_str() + token.size() && errno != ERANGE && std::isfinite(value);
}

/// A non-negative integer of at most 18 digits filling the whole token (an optional '+').
bool parse_count(const std::string& token, std::uint64_t& value) {
  std::size_t k = token.size() > 1 && token[0] == '+' ? 1 : 0;
  if (token.size() == k || token.size() - k > 18) return false;
  value = 0;
  for (; k < token.size(); ++k) {
    if (token[k] < '0' || token[k] > '9') return false;
    value = 10 * value + std::uint64_t(token[k] - '0');
  }
  return true;
}

std::vector<std::string> split_words(const std::string& line) {
  std::vector<std::string> words;
  std::size_t k = 0;
  while (k < line.size()) {
    while (k < line.size() && std::isspace(static_cast<unsigned char>(line[k]))) ++k;
    const std::size_t start = k;
    while (k < line.size() && !std::isspace(static_cast<unsigned char>(line[k]))) ++k;
    if (k > start) words.push_back(line.substr(start, k - start));
  }
  return words;
}

// --- OFF ----------------------------------------------------------------------------------------

/// The words of every line that has any, comments removed.
std::vector<std::vector<std::string>> off_lines(const std::string& text) {
  std::vector<std::vector<std::string>> lines;
  std::size_t start = 0;
  while (start <= text.size()) {
    std::size_t end = text.find('\n', start);
    if (end == std::string::npos) end = text.size();
    std::string line = text.substr(start, end - start);
    line = line.substr(0, line.find('#'));
    std::vector<std::string> words = split_words(line);
    if (!words.empty()) lines.push_back(std::move(words));
    start = end + 1;
  }
  return lines;
}

/// True for OFF, COFF, NOFF, CNOFF, STOFF, STCNOFF, … ; refuses 4D, nD and binary OFF.
bool is_off_keyword(const std::vector<std::string>& words) {
  const std::string& w = words[0];
  if (w.size() < 3 || w.compare(w.size() - 3, 3, "OFF") != 0) return false;
  std::string prefix = w.substr(0, w.size() - 3);
  if (prefix.find('4') != std::string::npos || prefix.find('n') != std::string::npos)
    refuse("OFF with 4D or nD vertices ('" + w + "') is not a 3D surface");
  if (prefix.compare(0, 2, "ST") == 0) prefix.erase(0, 2);
  if (!prefix.empty() && prefix[0] == 'C') prefix.erase(0, 1);
  if (!prefix.empty() && prefix[0] == 'N') prefix.erase(0, 1);
  if (!prefix.empty()) refuse("unknown OFF keyword '" + w + "'");
  if (words.size() > 1 && words[1] == "BINARY")
    refuse("binary OFF is not read (write it as ASCII OFF, STL, OBJ or PLY)");
  return true;
}

}  // namespace

PolygonSoup read_off_soup(const std::string& text) {
  const std::vector<std::vector<std::string>> lines = off_lines(text);
  if (lines.empty()) refuse("empty file");
  std::size_t at = 0;
  std::vector<std::string> counts = lines[0];
  if (is_off_keyword(lines[0])) {
    counts.erase(counts.begin());  // "OFF 8 6 0" on one line is allowed
    if (counts.empty()) {
      if (lines.size() < 2) refuse("no vertex and face counts after the OFF keyword");
      counts = lines[++at];
    }
  } else if (!counts.empty() && counts[0].find("OFF") != std::string::npos) {
    refuse("unknown OFF keyword '" + counts[0] + "'");
  }
  ++at;
  std::uint64_t nv = 0, nf = 0;
  if (counts.size() < 2 || !parse_count(counts[0], nv) || !parse_count(counts[1], nf))
    refuse("the counts line must start with the vertex and face counts");
  // One line per vertex and per face: a count beyond the file's lines is refused before any
  // allocation.
  const std::uint64_t left = lines.size() - at;
  if (nv > left || nf > left - nv)
    refuse("the header counts " + std::to_string(nv) + " vertices and " + std::to_string(nf) +
           " faces, but the file has only " + std::to_string(left) + " lines for them");
  PolygonSoup soup;
  soup.points.reserve(nv);
  for (std::uint64_t v = 0; v < nv; ++v, ++at) {
    const auto& w = lines[at];
    Eigen::Vector3d p;
    if (w.size() < 3 || !parse_real(w[0], p.x()) || !parse_real(w[1], p.y()) ||
        !parse_real(w[2], p.z()))
      refuse("vertex #" + std::to_string(v) + " is not three finite numbers");
    soup.points.push_back(p);
  }
  soup.polygons.reserve(nf);
  for (std::uint64_t f = 0; f < nf; ++f, ++at) {
    const auto& w = lines[at];
    std::uint64_t n = 0;
    if (!parse_count(w[0], n) || n + 1 > w.size())
      refuse("face #" + std::to_string(f) + " must list its vertex count, then that many indices");
    std::vector<std::size_t> poly(n);
    for (std::uint64_t k = 0; k < n; ++k) {
      std::uint64_t i = 0;
      if (!parse_count(w[k + 1], i))
        refuse("face #" + std::to_string(f) + ": vertex index '" + w[k + 1] +
               "' is not a non-negative integer");
      if (i >= nv) refuse("face #" + std::to_string(f) + " has a vertex index out of range");
      poly[k] = std::size_t(i);
    }
    soup.polygons.push_back(std::move(poly));
  }
  // More faces than counted: the count is off, and the faces it drops would be a hole.
  if (at < lines.size())
    refuse("the header counts " + std::to_string(nf) + " faces, but " +
           std::to_string(lines.size() - at) + " more lines follow them (a wrong face count?)");
  return soup;
}

// --- PLY ----------------------------------------------------------------------------------------

namespace {

enum class PlyFormat { ascii, little, big };

struct PlyType {
  int bytes = 0;
  bool integer = false, is_signed = false;
};

struct PlyProperty {
  std::string name;
  bool list = false;
  PlyType count, value;  ///< count: the list length's type (lists only)
};

struct PlyElement {
  std::string name;
  std::uint64_t count = 0;
  std::vector<PlyProperty> properties;
};

struct PlyHeader {
  PlyFormat format = PlyFormat::ascii;
  std::vector<PlyElement> elements;
  std::size_t body = 0;  ///< offset of the first byte after end_header's line
};

PlyType ply_type(const std::string& name) {
  static const std::map<std::string, PlyType> types = {
      {"char", {1, true, true}},    {"int8", {1, true, true}},     {"uchar", {1, true, false}},
      {"uint8", {1, true, false}},  {"short", {2, true, true}},    {"int16", {2, true, true}},
      {"ushort", {2, true, false}}, {"uint16", {2, true, false}},  {"int", {4, true, true}},
      {"int32", {4, true, true}},   {"uint", {4, true, false}},    {"uint32", {4, true, false}},
      {"float", {4, false, true}},  {"float32", {4, false, true}}, {"double", {8, false, true}},
      {"float64", {8, false, true}}};
  const auto it = types.find(name);
  if (it == types.end()) refuse("unknown PLY property type '" + name + "'");
  return it->second;
}

/// One header line (no line ending) into `h`; returns true at end_header.
bool ply_header_line(const std::vector<std::string>& w, PlyHeader& h, bool& have_format) {
  if (w.empty() || w[0] == "comment" || w[0] == "obj_info") return false;
  if (w[0] == "end_header") return true;
  if (w[0] == "format") {
    if (w.size() != 3 || w[2] != "1.0") refuse("PLY format line must be 'format <kind> 1.0'");
    if (w[1] == "ascii")
      h.format = PlyFormat::ascii;
    else if (w[1] == "binary_little_endian")
      h.format = PlyFormat::little;
    else if (w[1] == "binary_big_endian")
      h.format = PlyFormat::big;
    else
      refuse("unknown PLY format '" + w[1] + "'");
    have_format = true;
  } else if (w[0] == "element") {
    PlyElement e;
    if (w.size() != 3 || !parse_count(w[2], e.count))
      refuse("PLY element line must be 'element <name> <count>'");
    e.name = w[1];
    h.elements.push_back(e);
  } else if (w[0] == "property") {
    if (h.elements.empty()) refuse("PLY property before any element");
    PlyProperty p;
    if (w.size() == 3) {
      p.value = ply_type(w[1]);
      p.name = w[2];
    } else if (w.size() == 5 && w[1] == "list") {
      p.list = true;
      p.count = ply_type(w[2]);
      p.value = ply_type(w[3]);
      p.name = w[4];
      if (!p.count.integer) refuse("PLY list '" + p.name + "' has a non-integer length type");
    } else {
      refuse("PLY property line must be 'property <type> <name>' or 'property list …'");
    }
    h.elements.back().properties.push_back(p);
  } else {
    refuse("unknown PLY header line '" + w[0] + "'");
  }
  return false;
}

PlyHeader ply_header(const std::string& bytes) {
  PlyHeader h;
  bool have_format = false;
  std::size_t start = 0;
  for (int line = 0;; ++line) {
    const std::size_t end = bytes.find('\n', start);
    if (end == std::string::npos) refuse("the PLY header has no end_header line");
    std::string text = bytes.substr(start, end - start);
    if (!text.empty() && text.back() == '\r') text.pop_back();
    start = end + 1;
    if (line == 0) {
      if (text != "ply") refuse("not a PLY file (no 'ply' line first)");
      continue;
    }
    if (ply_header_line(split_words(text), h, have_format)) break;
  }
  if (!have_format) refuse("the PLY header has no format line");
  h.body = start;
  // Every instance of an element with properties takes at least one byte: counts beyond the
  // body's size are refused before any allocation.
  const std::uint64_t body_bytes = bytes.size() - h.body;
  for (const PlyElement& e : h.elements)
    if (e.count > 0 && (e.properties.empty() || e.count > body_bytes))
      refuse("PLY element '" + e.name + "' counts " + std::to_string(e.count) +
             " entries, more than the file holds");
  return h;
}

/// Reads the values of a PLY body, ASCII or binary, one at a time.
class PlyBody {
 public:
  PlyBody(const std::string& bytes, std::size_t at, PlyFormat format)
      : bytes_(bytes), at_(at), format_(format) {}

  /// A scalar as a double; an integer type gives its exact value.
  double value(const PlyType& t) {
    if (format_ == PlyFormat::ascii) return ascii_value(t);
    if (bytes_.size() - at_ < std::size_t(t.bytes)) refuse("the PLY body ends early");
    unsigned char b[8];
    std::memcpy(b, bytes_.data() + at_, std::size_t(t.bytes));
    at_ += std::size_t(t.bytes);
    if (format_ == PlyFormat::big)
      for (int k = 0; k < t.bytes / 2; ++k) std::swap(b[k], b[t.bytes - 1 - k]);
    return decode(b, t);
  }

  /// What is left to read (bytes, or characters in ASCII): a bound for list lengths.
  std::size_t left() const { return bytes_.size() - at_; }

 private:
  static double decode(const unsigned char* b, const PlyType& t) {  // little-endian bytes
    if (!t.integer) {
      if (t.bytes == 4) {
        float f;
        std::memcpy(&f, b, 4);
        return double(f);
      }
      double d;
      std::memcpy(&d, b, 8);
      return d;
    }
    std::uint64_t u = 0;
    for (int k = t.bytes - 1; k >= 0; --k) u = (u << 8) | b[k];
    if (t.is_signed && (u >> (8 * t.bytes - 1)) != 0)
      return double(std::int64_t(u) - (std::int64_t(1) << (8 * t.bytes)));
    return double(u);
  }

  double ascii_value(const PlyType& t) {
    while (at_ < bytes_.size() && std::isspace(static_cast<unsigned char>(bytes_[at_]))) ++at_;
    const std::size_t start = at_;
    while (at_ < bytes_.size() && !std::isspace(static_cast<unsigned char>(bytes_[at_]))) ++at_;
    if (at_ == start) refuse("the PLY body ends early");
    const std::string token = bytes_.substr(start, at_ - start);
    double v = 0;
    // An integer type's value must also fit the type (fuzzing found 1e85 as an "int" index).
    const double top = std::ldexp(1.0, 8 * t.bytes - (t.is_signed ? 1 : 0));
    if (!parse_real(token, v) ||
        (t.integer && (v != std::floor(v) || v >= top || v < (t.is_signed ? -top : 0.0))))
      refuse("PLY value '" + token.substr(0, 40) + "' is not a " +
             (t.integer ? "finite integer" : "finite number"));
    return v;
  }

  const std::string& bytes_;
  std::size_t at_;
  PlyFormat format_;
};

/// The list length read before a list's values, bounded by what is left of the body.
std::size_t ply_list_length(PlyBody& body, const PlyProperty& p) {
  const double n = body.value(p.count);
  if (!(n >= 0) || n > double(body.left()))
    refuse("PLY list '" + p.name + "' has a length beyond the file");
  return std::size_t(n);
}

bool is_face_list(const PlyElement& e, const PlyProperty& p) {
  return e.name == "face" && p.list && (p.name == "vertex_indices" || p.name == "vertex_index");
}

/// One instance of `e` into `soup` (vertex: x, y, z; face: its index list).
void ply_instance(PlyBody& body, const PlyElement& e, PolygonSoup& soup) {
  Eigen::Vector3d xyz = Eigen::Vector3d::Zero();
  for (const PlyProperty& p : e.properties) {
    if (!p.list) {
      const double v = body.value(p.value);
      if (e.name == "vertex" && (p.name == "x" || p.name == "y" || p.name == "z")) {
        if (!std::isfinite(v))
          refuse("vertex #" + std::to_string(soup.points.size()) + " has non-finite coordinates");
        xyz[p.name[0] - 'x'] = v;
      }
      continue;
    }
    const std::size_t n = ply_list_length(body, p);
    if (!is_face_list(e, p)) {
      for (std::size_t k = 0; k < n; ++k) body.value(p.value);
      continue;
    }
    if (!p.value.integer) refuse("PLY face indices must have an integer type");
    std::vector<std::size_t> poly(n);
    for (std::size_t k = 0; k < n; ++k) {
      const double i = body.value(p.value);
      if (!(i >= 0))
        refuse("face #" + std::to_string(soup.polygons.size()) + " has a negative vertex index");
      poly[k] = std::size_t(i);  // an integer type's value: exact, < 2^32
    }
    soup.polygons.push_back(std::move(poly));
  }
  if (e.name == "vertex") soup.points.push_back(xyz);
}

}  // namespace

PolygonSoup read_ply_soup(const std::string& bytes) {
  const PlyHeader h = ply_header(bytes);
  bool vertex_xyz = false;
  for (const PlyElement& e : h.elements) {
    if (e.name != "vertex") continue;
    int found = 0;
    for (const PlyProperty& p : e.properties)
      found += !p.list && (p.name == "x" || p.name == "y" || p.name == "z");
    vertex_xyz = found == 3;
  }
  if (!vertex_xyz) refuse("the PLY file has no vertex element with x, y and z");
  PolygonSoup soup;
  PlyBody body(bytes, h.body, h.format);
  for (const PlyElement& e : h.elements)
    for (std::uint64_t k = 0; k < e.count; ++k) ply_instance(body, e, soup);
  for (std::size_t f = 0; f < soup.polygons.size(); ++f)
    for (const std::size_t i : soup.polygons[f])
      if (i >= soup.points.size())
        refuse("face #" + std::to_string(f) + " has a vertex index out of range");
  return soup;
}

}  // namespace spinesim::mesh::detail
