// VTU (VTK XML UnstructuredGrid) writer and reader; layout and contract in io.hpp.
#include "spinesim/mesh/io.hpp"

#include "spinesim/common/atomic_file.hpp"
#include "xml_escape.hpp"
#include "write_checks.hpp"

#include <tinyxml2.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <limits>
#include <ostream>
#include <stdexcept>
#include <string>
#include <vector>

namespace spinesim::mesh {
namespace {

bool host_is_little_endian() {
  const std::uint16_t one = 1;
  unsigned char b;
  std::memcpy(&b, &one, 1);
  return b == 1;
}

// ------------------------------------------------------------------------------------------
// Base64 (RFC 4648, standard alphabet)

constexpr char kB64[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";

void base64_encode(const std::vector<unsigned char>& in, std::ostream& os) {
  std::string out;
  out.reserve((in.size() + 2) / 3 * 4);
  std::size_t i = 0;
  for (; i + 3 <= in.size(); i += 3) {
    const std::uint32_t w = (std::uint32_t(in[i]) << 16) | (std::uint32_t(in[i + 1]) << 8) | in[i + 2];
    out += kB64[(w >> 18) & 63];
    out += kB64[(w >> 12) & 63];
    out += kB64[(w >> 6) & 63];
    out += kB64[w & 63];
  }
  const std::size_t rest = in.size() - i;
  if (rest > 0) {
    std::uint32_t w = std::uint32_t(in[i]) << 16;
    if (rest == 2) w |= std::uint32_t(in[i + 1]) << 8;
    out += kB64[(w >> 18) & 63];
    out += kB64[(w >> 12) & 63];
    out += rest == 2 ? kB64[(w >> 6) & 63] : '=';
    out += '=';
  }
  os << out;
}

int b64_value(char c) {
  if (c >= 'A' && c <= 'Z') return c - 'A';
  if (c >= 'a' && c <= 'z') return c - 'a' + 26;
  if (c >= '0' && c <= '9') return c - '0' + 52;
  if (c == '+') return 62;
  if (c == '/') return 63;
  return -1;
}

/// Decodes base64 text, ignoring whitespace. Padding may also occur in the middle: VTK encodes
/// the block header and the data separately, meshio encodes them together; both decode to the
/// same byte sequence here. Returns false on an invalid character or a dangling partial quartet
/// (truncated text).
bool base64_decode(const char* s, std::vector<unsigned char>& out) {
  int quad[4];
  int nq = 0;
  for (; *s; ++s) {
    const char c = *s;
    if (c == ' ' || c == '\n' || c == '\r' || c == '\t') continue;
    if (c == '=') {
      // End of a padded quartet: 2 chars -> 1 byte, 3 chars -> 2 bytes.
      if (nq == 2) {
        out.push_back(static_cast<unsigned char>((quad[0] << 2) | (quad[1] >> 4)));
      } else if (nq == 3) {
        out.push_back(static_cast<unsigned char>((quad[0] << 2) | (quad[1] >> 4)));
        out.push_back(static_cast<unsigned char>(((quad[1] & 15) << 4) | (quad[2] >> 2)));
      } else if (nq != 0) {
        return false;
      }
      nq = 0;  // a second '=' of the same quartet arrives with nq == 0 and is skipped
      continue;
    }
    const int v = b64_value(c);
    if (v < 0) return false;
    quad[nq++] = v;
    if (nq == 4) {
      out.push_back(static_cast<unsigned char>((quad[0] << 2) | (quad[1] >> 4)));
      out.push_back(static_cast<unsigned char>(((quad[1] & 15) << 4) | (quad[2] >> 2)));
      out.push_back(static_cast<unsigned char>(((quad[2] & 3) << 6) | quad[3]));
      nq = 0;
    }
  }
  return nq == 0;
}

// ------------------------------------------------------------------------------------------
// Writing


template <class T>
void write_ascii_value(std::ostream& os, T v) {
  char buf[64];
  const auto res = std::to_chars(buf, buf + sizeof buf, v);  // shortest round-trip form
  os.write(buf, res.ptr - buf);
}

/// One <DataArray> with `n` values of C++ type T (VTK type name `vtk_type`), tuple-major.
template <class T>
void write_data_array(std::ostream& os, const char* vtk_type, const std::string& name, int ncomp,
                      const std::vector<T>& data, VtuEncoding enc, const char* indent) {
  os << indent << "<DataArray type=\"" << vtk_type << "\" Name=\"" << detail::xml_escape(name)
     << "\" NumberOfComponents=\"" << ncomp << "\" format=\""
     << (enc == VtuEncoding::binary ? "binary" : "ascii") << "\">\n"
     << indent << "  ";
  if (enc == VtuEncoding::binary) {
    const std::uint64_t nbytes = data.size() * sizeof(T);
    std::vector<unsigned char> bytes(sizeof nbytes + nbytes);
    std::memcpy(bytes.data(), &nbytes, sizeof nbytes);
    if (nbytes > 0) std::memcpy(bytes.data() + sizeof nbytes, data.data(), nbytes);
    base64_encode(bytes, os);  // header and data together, as meshio does
  } else {
    const std::size_t per_line = ncomp > 1 && ncomp <= 12 ? std::size_t(ncomp) : 6;
    for (std::size_t i = 0; i < data.size(); ++i) {
      if (i > 0) {
        if (i % per_line == 0) os << "\n" << indent << "  ";
        else os << ' ';
      }
      write_ascii_value(os, data[i]);
    }
  }
  os << "\n" << indent << "</DataArray>\n";
}

std::vector<double> row_major(const Eigen::MatrixXd& M) {
  std::vector<double> v(std::size_t(M.size()));
  std::size_t k = 0;
  for (Eigen::Index i = 0; i < M.rows(); ++i)
    for (Eigen::Index j = 0; j < M.cols(); ++j) v[k++] = M(i, j);
  return v;
}

void check_arrays(const std::string& path, const std::vector<DataArray>& arrays, Eigen::Index rows,
                  const char* kind, const char* reserved) {
  for (const DataArray& a : arrays) {
    const std::string head = "write_vtu: " + path + ": " + kind + " array '" + a.name + "'";
    if (a.name.empty())
      throw std::invalid_argument("write_vtu: " + path + ": a " + kind + " array has no name");
    if (a.name == reserved)
      throw std::invalid_argument(head + " uses a reserved name (written from the mesh labels)");
    if (a.values.rows() != rows || a.values.cols() < 1)
      throw std::invalid_argument(head + " has " + std::to_string(a.values.rows()) + "x" +
                                  std::to_string(a.values.cols()) + " values, expected " +
                                  std::to_string(rows) + " rows");
    if (!a.values.allFinite()) throw std::invalid_argument(head + " contains non-finite values");
  }
  for (std::size_t i = 0; i < arrays.size(); ++i)
    for (std::size_t j = 0; j < i; ++j)
      if (arrays[i].name == arrays[j].name)
        throw std::invalid_argument("write_vtu: " + path + ": two " + kind + " arrays named '" +
                                    arrays[i].name + "'");
}

// ------------------------------------------------------------------------------------------
// Reading

struct Reader {
  std::string path;
  bool swap_bytes = false;
  int header_bytes = 4;  // UInt32 by default (VTK XML format 0.1 and 1.0)

  [[noreturn]] void fail(const std::string& msg) const {
    throw std::invalid_argument("read_vtu: " + path + ": " + msg);
  }
};

/// A DataArray decoded to doubles (exact for every integer below 2^53 and every Float64).
struct RawArray {
  std::string name;
  int ncomp = 1;
  std::vector<double> v;
};

struct VtkType {
  int size;
  char kind;  // 'i' signed, 'u' unsigned, 'f' float
};

bool vtk_type(const std::string& t, VtkType& out) {
  static const struct { const char* name; VtkType type; } table[] = {
      {"Int8", {1, 'i'}},    {"UInt8", {1, 'u'}},   {"Int16", {2, 'i'}},   {"UInt16", {2, 'u'}},
      {"Int32", {4, 'i'}},   {"UInt32", {4, 'u'}},  {"Int64", {8, 'i'}},   {"UInt64", {8, 'u'}},
      {"Float32", {4, 'f'}}, {"Float64", {8, 'f'}}, {"String", {1, 'u'}}, {"Char", {1, 'i'}},
  };
  for (const auto& e : table)
    if (t == e.name) {
      out = e.type;
      return true;
    }
  return false;
}

double decode_value(const unsigned char* p, VtkType t, bool swap) {
  unsigned char b[8];
  std::memcpy(b, p, std::size_t(t.size));
  if (swap) std::reverse(b, b + t.size);
  switch (t.kind) {
    case 'f':
      if (t.size == 4) {
        float f;
        std::memcpy(&f, b, 4);
        return f;
      } else {
        double d;
        std::memcpy(&d, b, 8);
        return d;
      }
    case 'i': {
      std::int64_t v = 0;
      if (t.size == 1) { std::int8_t x; std::memcpy(&x, b, 1); v = x; }
      if (t.size == 2) { std::int16_t x; std::memcpy(&x, b, 2); v = x; }
      if (t.size == 4) { std::int32_t x; std::memcpy(&x, b, 4); v = x; }
      if (t.size == 8) { std::int64_t x; std::memcpy(&x, b, 8); v = x; }
      return double(v);
    }
    default: {
      std::uint64_t v = 0;
      if (t.size == 1) { std::uint8_t x; std::memcpy(&x, b, 1); v = x; }
      if (t.size == 2) { std::uint16_t x; std::memcpy(&x, b, 2); v = x; }
      if (t.size == 4) { std::uint32_t x; std::memcpy(&x, b, 4); v = x; }
      if (t.size == 8) { std::uint64_t x; std::memcpy(&x, b, 8); v = x; }
      return double(v);
    }
  }
}

std::vector<double> parse_ascii(const Reader& r, const std::string& name, const char* s) {
  std::vector<double> v;
  if (!s) return v;
  const char* end = s + std::strlen(s);
  while (true) {
    while (s < end && (*s == ' ' || *s == '\n' || *s == '\r' || *s == '\t')) ++s;
    if (s == end) break;
    if (*s == '+') ++s;
    double x;
    const auto res = std::from_chars(s, end, x);
    if (res.ec != std::errc() || (res.ptr < end && !std::isspace(static_cast<unsigned char>(*res.ptr))))
    {
      const char* tok_end = s;
      while (tok_end < end && tok_end - s < 24 && !std::isspace(static_cast<unsigned char>(*tok_end))) ++tok_end;
      r.fail("DataArray '" + name + "' has a value that is not a number: \"" +
             std::string(s, tok_end) + "\"");
    }
    v.push_back(x);
    s = res.ptr;
  }
  return v;
}

std::vector<double> decode_binary(const Reader& r, const std::string& name, const char* text,
                                  VtkType t) {
  std::vector<unsigned char> bytes;
  if (!text || !base64_decode(text, bytes))
    r.fail("DataArray '" + name + "' has invalid or truncated base64 data");
  if (bytes.size() < std::size_t(r.header_bytes))
    r.fail("DataArray '" + name + "' binary data is truncated (no block header)");
  std::uint64_t nbytes =
      std::uint64_t(decode_value(bytes.data(), VtkType{r.header_bytes, 'u'}, r.swap_bytes));
  if (bytes.size() - std::size_t(r.header_bytes) < nbytes)
    r.fail("DataArray '" + name + "' binary data is truncated (header says " +
           std::to_string(nbytes) + " bytes, found " +
           std::to_string(bytes.size() - std::size_t(r.header_bytes)) + ")");
  if (nbytes % std::uint64_t(t.size) != 0)
    r.fail("DataArray '" + name + "' byte count " + std::to_string(nbytes) +
           " is not a multiple of the value size");
  std::vector<double> v(nbytes / std::uint64_t(t.size));
  const unsigned char* p = bytes.data() + r.header_bytes;
  for (std::size_t i = 0; i < v.size(); ++i) v[i] = decode_value(p + i * std::size_t(t.size), t, r.swap_bytes);
  return v;
}

RawArray read_array(const Reader& r, const tinyxml2::XMLElement* da) {
  RawArray a;
  const char* name = da->Attribute("Name");
  a.name = name ? name : "";
  const std::string label = a.name.empty() ? std::string("(unnamed)") : a.name;
  const char* type = da->Attribute("type");
  VtkType t{};
  if (!type || !vtk_type(type, t))
    r.fail("DataArray '" + label + "' has unsupported type '" + (type ? type : "") + "'");
  a.ncomp = da->IntAttribute("NumberOfComponents", 1);
  if (a.ncomp < 1) r.fail("DataArray '" + label + "' has NumberOfComponents < 1");
  const char* fmt = da->Attribute("format");
  const std::string format = fmt ? fmt : "ascii";
  if (format == "ascii") {
    a.v = parse_ascii(r, label, da->GetText());
  } else if (format == "binary") {
    a.v = decode_binary(r, label, da->GetText(), t);
  } else if (format == "appended") {
    r.fail("uses appended data (format=\"appended\"), which is not supported; re-save it as ASCII "
           "or inline binary (ParaView: Data Mode Ascii or Binary; meshio: binary=False)");
  } else {
    r.fail("DataArray '" + label + "' has unknown format '" + format + "'");
  }
  if (a.v.size() % std::size_t(a.ncomp) != 0)
    r.fail("DataArray '" + label + "' has " + std::to_string(a.v.size()) +
           " values, not a multiple of NumberOfComponents " + std::to_string(a.ncomp));
  return a;
}

std::vector<RawArray> read_arrays(const Reader& r, const tinyxml2::XMLElement* parent) {
  std::vector<RawArray> out;
  if (!parent) return out;
  for (auto* da = parent->FirstChildElement("DataArray"); da; da = da->NextSiblingElement("DataArray"))
    out.push_back(read_array(r, da));
  return out;
}

const tinyxml2::XMLElement* find_named(const tinyxml2::XMLElement* parent, const char* name) {
  if (!parent) return nullptr;
  for (auto* da = parent->FirstChildElement("DataArray"); da; da = da->NextSiblingElement("DataArray")) {
    const char* n = da->Attribute("Name");
    if (n && std::strcmp(n, name) == 0) return da;
  }
  return nullptr;
}

/// Integer view of an array that must hold integers in [lo, hi].
std::vector<std::int64_t> as_integers(const Reader& r, const RawArray& a, double lo, double hi) {
  std::vector<std::int64_t> out(a.v.size());
  for (std::size_t i = 0; i < a.v.size(); ++i) {
    const double x = a.v[i];
    if (!(x >= lo && x <= hi) || x != std::floor(x))
      r.fail("'" + a.name + "' entry #" + std::to_string(i) + " = " + std::to_string(x) +
             " is not an integer in [" + std::to_string(std::int64_t(lo)) + ", " +
             std::to_string(std::int64_t(hi)) + "]");
    out[i] = std::int64_t(x);
  }
  return out;
}

Eigen::MatrixXd to_matrix(const RawArray& a) {
  const Eigen::Index rows = Eigen::Index(a.v.size()) / a.ncomp;
  Eigen::MatrixXd M(rows, a.ncomp);
  for (Eigen::Index i = 0; i < rows; ++i)
    for (int j = 0; j < a.ncomp; ++j) M(i, j) = a.v[std::size_t(i * a.ncomp + j)];
  return M;
}

/// Reads a PointData or CellData section of `count` tuples: the one-component integer label
/// array `label_name` goes into `labels` (left as it is when absent), every other array into
/// `others`.
void read_data_section(const Reader& r, const tinyxml2::XMLElement* section, const std::string& kind,
                       std::int64_t count, const std::string& label_name, Eigen::VectorXi& labels,
                       std::vector<DataArray>& others) {
  for (const RawArray& a : read_arrays(r, section)) {
    if (std::int64_t(a.v.size()) != count * a.ncomp)
      r.fail(kind + " '" + a.name + "' has " + std::to_string(a.v.size() / std::size_t(a.ncomp)) +
             " tuples, expected " + std::to_string(count));
    if (a.name == label_name) {
      if (a.ncomp != 1) r.fail(kind + " '" + label_name + "' must have 1 component");
      const auto s = as_integers(r, a, -2147483648.0, 2147483647.0);
      for (std::int64_t i = 0; i < count; ++i) labels(i) = int(s[std::size_t(i)]);
    } else {
      others.push_back({a.name, to_matrix(a)});
    }
  }
}

constexpr int kVtkTetra = 10;
constexpr int kVtkQuadraticTetra = 24;

std::string cell_type_name(std::int64_t type) {
  switch (type) {
    case 1: return "vertex (1)";
    case 3: return "line (3)";
    case 5: return "triangle (5)";
    case 9: return "quad (9)";
    case 12: return "hexahedron (12)";
    case 13: return "wedge (13)";
    case 14: return "pyramid (14)";
    case 22: return "quadratic triangle (22)";
    case 25: return "quadratic hexahedron (25)";
    default: return "VTK type " + std::to_string(type);
  }
}

}  // namespace

// ==========================================================================================

void write_vtu(const std::string& path, const TetMesh& m, const std::vector<DataArray>& point_data,
               const std::vector<DataArray>& cell_data, const VtuWriteOptions& options) {
  // 1. Refuse bad input before touching the disk.
  const std::string who = "write_vtu: " + path + ": ";
  detail::check_mesh_for_writing(m, who);
  if (!m.frame.origin_mm.allFinite() || !m.frame.axes.allFinite())
    throw std::invalid_argument(who + "disc frame contains non-finite values");
  check_arrays(path, point_data, m.num_vertices(), "point", "surface");
  check_arrays(path, cell_data, m.num_tets(), "cell", "region");
  if (!host_is_little_endian())
    throw std::runtime_error(who + "writing VTU on a big-endian host is not implemented");

  // 2. Flatten everything into VTK order.
  const std::size_t nt = std::size_t(m.num_tets());
  std::vector<std::int64_t> connectivity(4 * nt), offsets(nt);
  std::vector<std::uint8_t> types(nt, std::uint8_t(kVtkTetra));
  for (std::size_t t = 0; t < nt; ++t) {
    for (int k = 0; k < 4; ++k) connectivity[4 * t + std::size_t(k)] = m.T(Eigen::Index(t), k);
    offsets[t] = std::int64_t(4 * (t + 1));
  }
  const std::vector<std::int32_t> region(m.region.data(), m.region.data() + m.region.size());
  const std::vector<std::int32_t> surface(m.surface.data(), m.surface.data() + m.surface.size());
  std::vector<double> frame(12);
  for (int i = 0; i < 3; ++i) frame[std::size_t(i)] = m.frame.origin_mm(i);
  for (int c = 0; c < 3; ++c)
    for (int i = 0; i < 3; ++i) frame[std::size_t(3 + 3 * c + i)] = m.frame.axes(i, c);
  const std::vector<std::uint8_t> source(m.source.begin(), m.source.end());
  const VtuEncoding enc = options.encoding;

  // 3. Write to a temporary file, then rename.
  write_atomically("write_vtu", path, [&](std::ostream& os) {
    os << "<?xml version=\"1.0\"?>\n"
       << "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" "
          "header_type=\"UInt64\">\n"
       << "  <UnstructuredGrid>\n"
       << "    <FieldData>\n";
    write_data_array(os, "Float64", "disc_frame", 12, frame, VtuEncoding::ascii, "      ");
    if (!source.empty())
      write_data_array(os, "UInt8", "source", 1, source, VtuEncoding::ascii, "      ");
    os << "    </FieldData>\n"
       << "    <Piece NumberOfPoints=\"" << m.num_vertices() << "\" NumberOfCells=\"" << nt << "\">\n"
       << "      <PointData Scalars=\"surface\">\n";
    const char* in = "        ";
    write_data_array(os, "Int32", "surface", 1, surface, enc, in);
    for (const DataArray& a : point_data)
      write_data_array(os, "Float64", a.name, int(a.values.cols()), row_major(a.values), enc, in);
    os << "      </PointData>\n"
       << "      <CellData Scalars=\"region\">\n";
    write_data_array(os, "Int32", "region", 1, region, enc, in);
    for (const DataArray& a : cell_data)
      write_data_array(os, "Float64", a.name, int(a.values.cols()), row_major(a.values), enc, in);
    os << "      </CellData>\n"
       << "      <Points>\n";
    write_data_array(os, "Float64", "Points", 3, row_major(m.V), enc, in);
    os << "      </Points>\n"
       << "      <Cells>\n";
    write_data_array(os, "Int64", "connectivity", 1, connectivity, enc, in);
    write_data_array(os, "Int64", "offsets", 1, offsets, enc, in);
    write_data_array(os, "UInt8", "types", 1, types, enc, in);
    os << "      </Cells>\n"
       << "    </Piece>\n"
       << "  </UnstructuredGrid>\n"
       << "</VTKFile>\n";
  });
}

// ==========================================================================================

TetMesh read_vtu(const std::string& path, std::vector<DataArray>* point_data,
                 std::vector<DataArray>* cell_data) {
  using tinyxml2::XMLElement;
  Reader r;
  r.path = path;

  // 1. File and XML envelope.
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) r.fail("no such file");
  tinyxml2::XMLDocument doc;
  if (doc.LoadFile(path.c_str()) != tinyxml2::XML_SUCCESS) {
    std::string err = doc.ErrorStr() ? doc.ErrorStr() : "unknown error";
    std::replace(err.begin(), err.end(), '\n', ' ');
    r.fail("not a readable XML file (" + err + ")");
  }
  const XMLElement* root = doc.RootElement();
  if (!root || std::strcmp(root->Name(), "VTKFile") != 0) r.fail("not a VTK XML file (no <VTKFile>)");
  const char* ftype = root->Attribute("type");
  if (!ftype || std::strcmp(ftype, "UnstructuredGrid") != 0)
    r.fail(std::string("not an UnstructuredGrid (VTKFile type=\"") + (ftype ? ftype : "") + "\")");
  if (const char* comp = root->Attribute("compressor"))
    r.fail(std::string("compressed data (compressor=\"") + comp +
           "\") is not supported; re-save it uncompressed (ParaView: Compressor Type None; "
           "meshio: compression=None) or as ASCII");
  if (root->FirstChildElement("AppendedData"))
    r.fail("uses appended data (<AppendedData>), which is not supported; re-save it as ASCII or "
           "inline binary (ParaView: Data Mode Ascii or Binary; meshio: binary=False)");
  const char* order = root->Attribute("byte_order");
  const bool file_little = !order || std::strcmp(order, "BigEndian") != 0;
  r.swap_bytes = file_little != host_is_little_endian();
  if (const char* ht = root->Attribute("header_type")) {
    if (std::strcmp(ht, "UInt32") == 0) r.header_bytes = 4;
    else if (std::strcmp(ht, "UInt64") == 0) r.header_bytes = 8;
    else r.fail(std::string("unsupported header_type \"") + ht + "\"");
  }
  const XMLElement* grid = root->FirstChildElement("UnstructuredGrid");
  if (!grid) r.fail("no <UnstructuredGrid> element");
  const XMLElement* piece = grid->FirstChildElement("Piece");
  if (!piece) r.fail("no <Piece> element");
  if (piece->NextSiblingElement("Piece")) r.fail("has more than one Piece; merge them into one first");

  std::int64_t np = -1, nc = -1;
  if (piece->QueryInt64Attribute("NumberOfPoints", &np) != tinyxml2::XML_SUCCESS || np < 0)
    r.fail("Piece has no valid NumberOfPoints");
  if (piece->QueryInt64Attribute("NumberOfCells", &nc) != tinyxml2::XML_SUCCESS || nc < 0)
    r.fail("Piece has no valid NumberOfCells");
  if (np == 0 || nc == 0) r.fail("mesh is empty (NumberOfPoints or NumberOfCells is 0)");

  // 2. Points.
  const XMLElement* points_el = piece->FirstChildElement("Points");
  const XMLElement* pda = points_el ? points_el->FirstChildElement("DataArray") : nullptr;
  if (!pda) r.fail("no <Points> DataArray");
  RawArray pts = read_array(r, pda);
  if (pts.ncomp != 3) r.fail("Points must have 3 components, found " + std::to_string(pts.ncomp));
  if (std::int64_t(pts.v.size()) != 3 * np)
    r.fail("Points has " + std::to_string(pts.v.size() / 3) + " points, NumberOfPoints says " +
           std::to_string(np));
  for (double x : pts.v)
    if (!std::isfinite(x)) r.fail("point coordinates contain non-finite values");

  // 3. Cells.
  const XMLElement* cells_el = piece->FirstChildElement("Cells");
  if (!cells_el) r.fail("no <Cells> element");
  auto cell_array = [&](const char* name) {
    const XMLElement* da = find_named(cells_el, name);
    if (!da) r.fail(std::string("Cells has no '") + name + "' DataArray");
    RawArray a = read_array(r, da);
    a.name = name;
    return a;
  };
  const auto conn = as_integers(r, cell_array("connectivity"), 0, double(np - 1));
  const auto offs = as_integers(r, cell_array("offsets"), 0, 9e15);
  const auto types = as_integers(r, cell_array("types"), 0, 255);
  if (std::int64_t(offs.size()) != nc || std::int64_t(types.size()) != nc)
    r.fail("Cells offsets/types have " + std::to_string(offs.size()) + "/" +
           std::to_string(types.size()) + " entries, NumberOfCells says " + std::to_string(nc));
  bool any_quadratic = false;
  TetMesh m;
  m.T.resize(nc, 4);
  std::int64_t start = 0;
  for (std::int64_t c = 0; c < nc; ++c) {
    const std::int64_t type = types[std::size_t(c)];
    std::int64_t want = 0;
    if (type == kVtkTetra) want = 4;
    else if (type == kVtkQuadraticTetra) want = 10, any_quadratic = true;
    else
      r.fail("cell #" + std::to_string(c) + " is a " + cell_type_name(type) +
             "; only tetrahedra (VTK types 10 and 24) are supported");
    const std::int64_t end = offs[std::size_t(c)];
    if (end - start != want || end > std::int64_t(conn.size()))
      r.fail("cell #" + std::to_string(c) + " offsets are inconsistent with its type");
    for (int k = 0; k < 4; ++k) m.T(c, k) = int(conn[std::size_t(start + k)]);
    start = end;
  }
  if (start != std::int64_t(conn.size()))
    r.fail("connectivity has " + std::to_string(conn.size()) + " entries, the offsets use " +
           std::to_string(start));

  m.V.resize(np, 3);
  for (std::int64_t i = 0; i < np; ++i)
    for (int j = 0; j < 3; ++j) m.V(i, j) = pts.v[std::size_t(3 * i + j)];

  // 4. Point and cell data.
  m.surface = Eigen::VectorXi::Zero(np);
  m.region = Eigen::VectorXi::Ones(nc);
  std::vector<DataArray> pdata, cdata;
  read_data_section(r, piece->FirstChildElement("PointData"), "PointData", np, "surface", m.surface, pdata);
  read_data_section(r, piece->FirstChildElement("CellData"), "CellData", nc, "region", m.region, cdata);

  // 5. FieldData: frame and provenance (other field arrays are ignored, not decoded).
  m.source = path;
  const XMLElement* field = grid->FirstChildElement("FieldData");
  if (const XMLElement* da = find_named(field, "disc_frame")) {
    const RawArray f = read_array(r, da);
    if (f.v.size() != 12) r.fail("FieldData 'disc_frame' must have 12 values");
    for (double x : f.v)
      if (!std::isfinite(x)) r.fail("FieldData 'disc_frame' contains non-finite values");
    for (int i = 0; i < 3; ++i) m.frame.origin_mm(i) = f.v[std::size_t(i)];
    for (int c = 0; c < 3; ++c)
      for (int i = 0; i < 3; ++i) m.frame.axes(i, c) = f.v[std::size_t(3 + 3 * c + i)];
  }
  if (const XMLElement* da = find_named(field, "source")) {
    const RawArray s = read_array(r, da);
    std::string text;
    for (double c : s.v) {
      if (c == 0) break;  // VTK String arrays are NUL-terminated
      if (c > 0 && c < 256) text += char(int(c));
    }
    if (!text.empty()) m.source = text;
  }

  // 6. Quadratic tets: keep only the vertices used as corners, remap indices and point arrays.
  if (any_quadratic) {
    std::vector<int> new_index(std::size_t(np), -1);
    int used = 0;
    for (Eigen::Index t = 0; t < m.T.rows(); ++t)
      for (int k = 0; k < 4; ++k) {
        int& ni = new_index[std::size_t(m.T(t, k))];
        if (ni < 0) ni = used++;
      }
    Eigen::MatrixX3d V(used, 3);
    Eigen::VectorXi surf(used);
    for (std::int64_t i = 0; i < np; ++i) {
      const int ni = new_index[std::size_t(i)];
      if (ni < 0) continue;
      V.row(ni) = m.V.row(i);
      surf(ni) = m.surface(i);
    }
    for (DataArray& a : pdata) {
      Eigen::MatrixXd vals(used, a.values.cols());
      for (std::int64_t i = 0; i < np; ++i)
        if (new_index[std::size_t(i)] >= 0) vals.row(new_index[std::size_t(i)]) = a.values.row(i);
      a.values = std::move(vals);
    }
    for (Eigen::Index t = 0; t < m.T.rows(); ++t)
      for (int k = 0; k < 4; ++k) m.T(t, k) = new_index[std::size_t(m.T(t, k))];
    m.V = std::move(V);
    m.surface = std::move(surf);
  }

  // 7. Geometric sanity (inverted / zero-volume tets) from the shared validator.
  try {
    validate(m);
  } catch (const std::invalid_argument& e) {
    r.fail(e.what());
  }
  if (point_data) *point_data = std::move(pdata);
  if (cell_data) *cell_data = std::move(cdata);
  return m;
}

}  // namespace spinesim::mesh
