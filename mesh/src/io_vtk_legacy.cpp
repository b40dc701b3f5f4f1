// Legacy VTK (.vtk) unstructured grids: ASCII and BINARY (big-endian), file versions 2.0–4.2
// (CELLS n size, each cell "count ids…") and 5.1 (CELLS with OFFSETS and CONNECTIVITY arrays).
// The grid goes through the same checks as a VTU (vtk_grid.hpp). Contract in io.hpp.
#include "spinesim/mesh/io.hpp"

#include "spinesim/common/input_file.hpp"

#include "vtk_grid.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <vector>

namespace spinesim::mesh {
namespace {

using detail::RawArray;

/// A legacy data type: its size in bytes in a BINARY file and whether it is a float.
struct LegacyType {
  int size = 0;
  char kind = 'f';  // 'i' signed, 'u' unsigned, 'f' float
};

bool legacy_type(std::string t, LegacyType& out) {
  std::transform(t.begin(), t.end(), t.begin(),
                 [](unsigned char c) { return char(std::tolower(c)); });
  static const struct {
    const char* name;
    LegacyType type;
  } table[] = {
      {"bit", {1, 'u'}},           {"unsigned_char", {1, 'u'}},
      {"char", {1, 'i'}},          {"unsigned_short", {2, 'u'}},
      {"short", {2, 'i'}},         {"unsigned_int", {4, 'u'}},
      {"int", {4, 'i'}},           {"unsigned_long", {8, 'u'}},
      {"long", {8, 'i'}},          {"float", {4, 'f'}},
      {"double", {8, 'f'}},        {"vtktypeint64", {8, 'i'}},
      {"vtktypeuint64", {8, 'u'}}, {"vtktypeint32", {4, 'i'}},
      {"vtktypeuint32", {4, 'u'}},
  };
  for (const auto& e : table)
    if (t == e.name) {
      out = e.type;
      return true;
    }
  return false;
}

/// A cursor over the file: keyword lines, then ASCII tokens or big-endian binary values.
class LegacyReader : public detail::FileError {
 public:
  LegacyReader(std::string path, std::string text) : text_(std::move(text)) {
    who = "read_vtk";
    this->path = std::move(path);
  }
  bool binary = false;
  int version_major = 0;
  /// The file's size: no count of values can exceed it (each takes a byte or more).
  std::size_t size() const { return text_.size(); }

  bool at_end() {
    skip_space();
    return pos_ >= text_.size();
  }
  /// The next line, trimmed (empty at the end of the file).
  std::string line() {
    std::size_t end = text_.find('\n', pos_);
    if (end == std::string::npos) end = text_.size();
    std::string s = text_.substr(pos_, end - pos_);
    pos_ = std::min(text_.size(), end + 1);
    while (!s.empty() && (s.back() == '\r' || s.back() == ' ' || s.back() == '\t')) s.pop_back();
    const std::size_t first = s.find_first_not_of(" \t");
    return first == std::string::npos ? std::string() : s.substr(first);
  }
  /// The next non-empty line, split into words.
  std::vector<std::string> words() {
    std::string s;
    while (s.empty() && pos_ < text_.size()) s = line();
    std::istringstream is(s);
    std::vector<std::string> w;
    for (std::string x; is >> x;) w.push_back(x);
    return w;
  }
  /// `n` values of type `t`.
  std::vector<double> values(std::int64_t n, const LegacyType& t, const std::string& what) {
    if (n < 0 || std::uint64_t(n) > (std::uint64_t(1) << 32))
      fail(what + ": implausible count " + std::to_string(n));
    std::vector<double> v;
    v.reserve(std::size_t(std::min<std::int64_t>(n, std::int64_t(text_.size()))));
    if (binary) {
      const std::size_t bytes = std::size_t(n) * std::size_t(t.size);
      if (text_.size() - pos_ < bytes) fail(what + ": binary data is truncated");
      for (std::int64_t i = 0; i < n; ++i)
        v.push_back(decode(reinterpret_cast<const unsigned char*>(text_.data()) + pos_ +
                               std::size_t(i) * std::size_t(t.size),
                           t));
      pos_ += bytes;
      if (pos_ < text_.size() && text_[pos_] == '\n') ++pos_;  // the newline after the data
      return v;
    }
    for (std::int64_t i = 0; i < n; ++i) {
      skip_space();
      if (pos_ >= text_.size())
        fail(what + ": expected " + std::to_string(n) + " values, found " + std::to_string(i));
      const char* s = text_.data() + pos_;
      const char* end = text_.data() + text_.size();
      if (*s == '+') ++s;
      double x = 0;
      const auto res = std::from_chars(s, end, x);
      if (res.ec != std::errc()) fail(what + ": '" + text_.substr(pos_, 20) + "' is not a number");
      v.push_back(x);
      pos_ = std::size_t(res.ptr - text_.data());
    }
    return v;
  }

 private:
  void skip_space() {
    while (pos_ < text_.size() && std::isspace(static_cast<unsigned char>(text_[pos_]))) ++pos_;
  }
  static double decode(const unsigned char* p, const LegacyType& t) {
    unsigned char b[8];
    for (int i = 0; i < t.size; ++i) b[i] = p[t.size - 1 - i];  // big-endian to little-endian
    if (t.kind == 'f') {
      if (t.size == 4) {
        float f;
        std::memcpy(&f, b, 4);
        return f;
      }
      double d;
      std::memcpy(&d, b, 8);
      return d;
    }
    std::uint64_t u = 0;
    std::memcpy(&u, b, std::size_t(t.size));
    if (t.kind == 'u') return double(u);
    const int shift = 64 - 8 * t.size;  // sign-extend
    return double(std::int64_t(u << shift) >> shift);
  }
  std::string text_;
  std::size_t pos_ = 0;
};

LegacyType type_of(LegacyReader& r, const std::string& name, const std::string& what) {
  LegacyType t;
  if (!legacy_type(name, t)) r.fail(what + ": unsupported data type '" + name + "'");
  return t;
}

std::int64_t count_of(LegacyReader& r, const std::string& word, const std::string& what) {
  std::int64_t n = -1;
  const auto res = std::from_chars(word.data(), word.data() + word.size(), n);
  if (res.ec != std::errc() || res.ptr != word.data() + word.size() || n < 0)
    r.fail(what + ": '" + word + "' is not a count");
  // Bounded by the file's size, so that products of counts (3 coordinates a point, components
  // times tuples) cannot overflow.
  if (std::uint64_t(n) > r.size())
    r.fail(what + ": the count " + word + " is more than the file's " + std::to_string(r.size()) +
           " bytes can hold");
  return n;
}

std::vector<std::int64_t> integers(LegacyReader& r, std::int64_t n, const LegacyType& t,
                                   const std::string& what) {
  RawArray a;
  a.name = what;
  a.v = r.values(n, t, what);
  return detail::as_integers(r, a, -9e15, 9e15);
}

/// CELLS: legacy "count ids…" lists (versions < 5) or OFFSETS + CONNECTIVITY (5.x).
void read_cells(LegacyReader& r, const std::vector<std::string>& w, detail::RawGrid& g) {
  if (w.size() < 3) r.fail("CELLS needs two counts");
  const std::int64_t a = count_of(r, w[1], "CELLS"), b = count_of(r, w[2], "CELLS");
  if (r.version_major >= 5) {
    const auto off_words = r.words();
    if (off_words.size() < 2 || off_words[0] != "OFFSETS") r.fail("CELLS: expected OFFSETS");
    auto offsets = integers(r, a, type_of(r, off_words[1], "OFFSETS"), "OFFSETS");
    const auto conn_words = r.words();
    if (conn_words.size() < 2 || conn_words[0] != "CONNECTIVITY")
      r.fail("CELLS: expected CONNECTIVITY");
    g.connectivity = integers(r, b, type_of(r, conn_words[1], "CONNECTIVITY"), "CONNECTIVITY");
    if (offsets.empty() || offsets.front() != 0) r.fail("OFFSETS must start at 0");
    g.num_cells = a - 1;
    g.offsets.assign(offsets.begin() + 1, offsets.end());
    return;
  }
  const auto list = integers(r, b, LegacyType{4, 'i'}, "CELLS");
  g.num_cells = a;
  std::size_t k = 0;
  for (std::int64_t c = 0; c < a; ++c) {
    if (k >= list.size() || list[k] < 0 || k + 1 + std::size_t(list[k]) > list.size())
      r.fail("CELLS: cell #" + std::to_string(c) + " runs past the list");
    const std::size_t count = std::size_t(list[k]);
    g.connectivity.insert(g.connectivity.end(), list.begin() + std::ptrdiff_t(k + 1),
                          list.begin() + std::ptrdiff_t(k + 1 + count));
    g.offsets.push_back(std::int64_t(g.connectivity.size()));
    k += 1 + count;
  }
  if (k != list.size())
    r.fail("CELLS: size " + std::to_string(b) + " does not match the cells listed");
}

/// The attribute arrays of a POINT_DATA or CELL_DATA section of `n` tuples, up to the next
/// section keyword (returned in `next`, empty at the end of the file).
std::vector<RawArray> read_attributes(LegacyReader& r, std::int64_t n,
                                      std::vector<std::string>& next) {
  std::vector<RawArray> out;
  while (!r.at_end()) {
    const auto w = r.words();
    if (w.empty()) break;
    const std::string& key = w[0];
    if (key == "POINT_DATA" || key == "CELL_DATA") {
      next = w;
      return out;
    }
    if (key == "METADATA") {  // VTK 9: INFORMATION blocks up to an empty line
      while (!r.at_end() && !r.line().empty()) {}
      continue;
    }
    if (key == "SCALARS") {
      if (w.size() < 3) r.fail("SCALARS needs a name and a type");
      RawArray a;
      a.name = w[1];
      a.ncomp = w.size() > 3 ? int(count_of(r, w[3], "SCALARS")) : 1;
      const LegacyType t = type_of(r, w[2], "SCALARS " + a.name);
      const auto lut = r.words();
      if (lut.empty() || lut[0] != "LOOKUP_TABLE")
        r.fail("SCALARS " + a.name + ": expected LOOKUP_TABLE");
      a.v = r.values(n * a.ncomp, t, "SCALARS " + a.name);
      out.push_back(std::move(a));
    } else if (key == "VECTORS" || key == "NORMALS" || key == "TENSORS") {
      if (w.size() < 3) r.fail(key + " needs a name and a type");
      RawArray a;
      a.name = w[1];
      a.ncomp = key == "TENSORS" ? 9 : 3;
      a.v = r.values(n * a.ncomp, type_of(r, w[2], key + " " + a.name), key + " " + a.name);
      out.push_back(std::move(a));
    } else if (key == "FIELD") {
      const std::int64_t arrays = w.size() > 2 ? count_of(r, w[2], "FIELD") : 0;
      for (std::int64_t i = 0; i < arrays; ++i) {
        const auto h = r.words();
        if (h.size() < 4)
          r.fail("FIELD array #" + std::to_string(i) + ": expected 'name components tuples type'");
        RawArray a;
        a.name = h[0];
        a.ncomp = int(count_of(r, h[1], "FIELD " + a.name));
        const std::int64_t tuples = count_of(r, h[2], "FIELD " + a.name);
        if (a.ncomp < 1) r.fail("FIELD " + a.name + ": components < 1");
        a.v = r.values(tuples * a.ncomp, type_of(r, h[3], "FIELD " + a.name), "FIELD " + a.name);
        out.push_back(std::move(a));
      }
    } else {
      r.fail("attribute '" + key +
             "' is not supported (SCALARS, VECTORS, NORMALS, TENSORS, FIELD are)");
    }
  }
  next.clear();
  return out;
}

/// Header: version, title, ASCII|BINARY, DATASET UNSTRUCTURED_GRID.
void read_header(LegacyReader& r) {
  const std::string first = r.line();
  const std::string tag = "# vtk DataFile Version ";
  if (first.compare(0, tag.size(), tag) != 0)
    r.fail("not a legacy VTK file (no '# vtk DataFile Version' line)");
  r.version_major = std::atoi(first.c_str() + tag.size());
  r.line();  // title
  const std::string mode = r.line();
  if (mode == "BINARY")
    r.binary = true;
  else if (mode != "ASCII")
    r.fail("third line must be ASCII or BINARY, found '" + mode + "'");
  const auto ds = r.words();
  if (ds.size() < 2 || ds[0] != "DATASET") r.fail("expected a DATASET line");
  if (ds[1] != "UNSTRUCTURED_GRID")
    r.fail("DATASET " + ds[1] + " is not an unstructured grid of tetrahedra");
}

}  // namespace

TetMesh read_vtk_legacy(const std::string& path, std::vector<DataArray>* point_data,
                        std::vector<DataArray>* cell_data) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec))
    detail::FileError{"read_vtk", path}.fail(path_kind(path).empty() ? "no such file"
                                                                     : "it is " + path_kind(path) +
                                                                           ", not a regular file");
  std::ifstream in(path, std::ios::binary);
  LegacyReader r(
      path, std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>()));
  record_input_file(path);
  read_header(r);
  detail::RawGrid g;
  bool have_points = false, have_types = false;
  std::vector<std::string> w = r.words();
  while (!w.empty()) {
    const std::string& key = w[0];
    std::vector<std::string> next;
    if (key == "POINTS" && w.size() >= 3) {
      g.num_points = count_of(r, w[1], "POINTS");
      g.points.name = "Points";
      g.points.ncomp = 3;
      g.points.v = r.values(3 * g.num_points, type_of(r, w[2], "POINTS"), "POINTS");
      have_points = true;
    } else if (key == "CELLS") {
      read_cells(r, w, g);
    } else if (key == "CELL_TYPES" && w.size() >= 2) {
      g.types = integers(r, count_of(r, w[1], "CELL_TYPES"), LegacyType{4, 'i'}, "CELL_TYPES");
      have_types = true;
    } else if (key == "POINT_DATA" || key == "CELL_DATA") {
      if (w.size() < 2) r.fail(key + " needs a count");
      const std::int64_t n = count_of(r, w[1], key);
      auto arrays = read_attributes(r, n, next);
      auto& dst = key == "POINT_DATA" ? g.point_data : g.cell_data;
      dst.insert(dst.end(), arrays.begin(), arrays.end());
      w = next;
      continue;
    } else if (key == "FIELD") {  // dataset-level field data: frame and provenance if present
      for (RawArray& a : read_attributes(r, 0, next))
        if (a.name == "disc_frame")
          g.disc_frame = a;
        else if (a.name == "source")
          g.source = a;
      w = next;
      continue;
    } else if (key == "METADATA") {
      while (!r.at_end() && !r.line().empty()) {}
    } else {
      r.fail("unexpected section '" + key + "'");
    }
    w = r.at_end() ? std::vector<std::string>() : r.words();
  }
  if (!have_points) r.fail("no POINTS section");
  if (!have_types) r.fail("no CELL_TYPES section");
  return detail::assemble_tet_mesh(r, std::move(g), point_data, cell_data);
}

TetMesh read_tet_mesh(const std::string& path, std::vector<DataArray>* point_data,
                      std::vector<DataArray>* cell_data) {
  // Only a regular file is opened here (a FIFO would block): read_vtu names anything else.
  if (path_kind(path) != "a regular file") return read_vtu(path, point_data, cell_data);
  std::ifstream in(path, std::ios::binary);
  char head[23] = {};
  in.read(head, sizeof head);
  if (in.gcount() == std::streamsize(sizeof head) &&
      std::string(head, sizeof head) == "# vtk DataFile Version ")
    return read_vtk_legacy(path, point_data, cell_data);
  // Neither a legacy VTK header nor XML (its first non-blank character is '<', after an optional
  // UTF-8 byte-order mark): name what is read rather than an XML parser's complaint.
  std::string start(head, std::size_t(in.gcount()));
  if (start.rfind("\xEF\xBB\xBF", 0) == 0) start.erase(0, 3);
  const auto first = start.find_first_not_of(" \t\r\n");
  if (first != std::string::npos && start[first] != '<')
    detail::FileError{"read_tet_mesh", path}.fail(
        "not a mesh file this program reads: a tetrahedral mesh is read from VTU (VTK XML "
        "UnstructuredGrid: ascii, binary, appended, zlib or lzma) or legacy VTK (.vtk, ASCII or "
        "binary); convert other formats with meshio (`meshio convert IN OUT.vtu`)");
  return read_vtu(path, point_data, cell_data);
}

}  // namespace spinesim::mesh
