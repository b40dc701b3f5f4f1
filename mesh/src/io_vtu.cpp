// VTU (VTK XML UnstructuredGrid) writer and reader; layout and contract in io.hpp.
#include "spinesim/mesh/io.hpp"

#include "spinesim/common/input_file.hpp"

#include "spinesim/common/atomic_file.hpp"
#include "spinesim/common/provenance.hpp"
#include "vtk_grid.hpp"
#include "write_checks.hpp"
#include "xml_escape.hpp"

#include <lz4.h>
#include <lzma.h>
#include <tinyxml2.h>
#include <zlib.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
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
    const std::uint32_t w =
        (std::uint32_t(in[i]) << 16) | (std::uint32_t(in[i + 1]) << 8) | in[i + 2];
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
bool base64_decode(const char* s, std::size_t n, std::vector<unsigned char>& out) {
  int quad[4];
  int nq = 0;
  for (const char* end = s + n; s < end; ++s) {
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

/// VTK's compressed layout: the header [#blocks, block size, last block size, compressed sizes…]
/// (UInt64) base64-encoded on its own, then the compressed blocks base64-encoded together.
void write_zlib_blocks(const unsigned char* data, std::size_t nbytes, std::ostream& os) {
  constexpr std::size_t kBlock = 32768;
  const std::size_t nblocks = (nbytes + kBlock - 1) / kBlock;
  std::vector<std::uint64_t> header = {nblocks, kBlock, nbytes % kBlock};
  std::vector<unsigned char> packed;
  for (std::size_t k = 0; k < nblocks; ++k) {
    const std::size_t size = std::min(kBlock, nbytes - k * kBlock);
    uLongf csize = compressBound(uLong(size));
    const std::size_t at = packed.size();
    packed.resize(at + csize);
    if (compress2(packed.data() + at, &csize, data + k * kBlock, uLong(size), 6) != Z_OK)
      throw std::runtime_error("write_vtu: zlib could not compress a block");
    packed.resize(at + csize);
    header.push_back(csize);
  }
  std::vector<unsigned char> head(header.size() * sizeof(std::uint64_t));
  std::memcpy(head.data(), header.data(), head.size());
  base64_encode(head, os);
  base64_encode(packed, os);
}

/// Whether a <DataArray> states its tuple count. VTK sizes the arrays of a Piece from the Piece,
/// but a <FieldData> array from its NumberOfTuples alone: without it VTK reads the array empty.
enum class Tuples { implied, stated };

/// One <DataArray> with `n` values of C++ type T (VTK type name `vtk_type`), tuple-major.
template <class T>
void write_data_array(std::ostream& os, const char* vtk_type, const std::string& name, int ncomp,
                      const std::vector<T>& data, VtuEncoding enc, const char* indent,
                      Tuples tuples = Tuples::implied) {
  os << indent << "<DataArray type=\"" << vtk_type << "\" Name=\"" << detail::xml_escape(name)
     << "\" NumberOfComponents=\"" << ncomp;
  if (tuples == Tuples::stated) os << "\" NumberOfTuples=\"" << data.size() / std::size_t(ncomp);
  os << "\" format=\""
     << (enc == VtuEncoding::ascii ? "ascii" : "binary") << "\">\n"
     << indent << "  ";
  if (enc == VtuEncoding::zlib) {
    write_zlib_blocks(reinterpret_cast<const unsigned char*>(data.data()), data.size() * sizeof(T),
                      os);
  } else if (enc == VtuEncoding::binary) {
    const std::uint64_t nbytes = data.size() * sizeof(T);
    std::vector<unsigned char> bytes(sizeof nbytes + nbytes);
    std::memcpy(bytes.data(), &nbytes, sizeof nbytes);
    if (nbytes > 0) std::memcpy(bytes.data() + sizeof nbytes, data.data(), nbytes);
    base64_encode(bytes, os);  // header and data together, as meshio does
  } else {
    const std::size_t per_line = ncomp > 1 && ncomp <= 12 ? std::size_t(ncomp) : 6;
    for (std::size_t i = 0; i < data.size(); ++i) {
      if (i > 0) {
        if (i % per_line == 0)
          os << "\n" << indent << "  ";
        else
          os << ' ';
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

/// The extra Float64 arrays of a PointData or CellData section.
void write_extra_arrays(std::ostream& os, const std::vector<DataArray>& arrays, VtuEncoding enc,
                        const char* indent) {
  for (const DataArray& a : arrays)
    write_data_array(os, "Float64", a.name, int(a.values.cols()), row_major(a.values), enc, indent);
}

/// <Points> and <Cells> (one VTK cell type, `cells` a row per cell) and the closing tags.
template <class Cells>
void write_points_cells_and_close(std::ostream& os, const Eigen::MatrixX3d& points,
                                  const Cells& cells, std::uint8_t vtk_type, VtuEncoding enc) {
  const char* in = "        ";
  const std::size_t n = std::size_t(cells.rows()), k = std::size_t(cells.cols());
  std::vector<std::int64_t> connectivity(k * n), offsets(n);
  const std::vector<std::uint8_t> types(n, vtk_type);
  for (std::size_t c = 0; c < n; ++c) {
    for (std::size_t j = 0; j < k; ++j)
      connectivity[k * c + j] = cells(Eigen::Index(c), Eigen::Index(j));
    offsets[c] = std::int64_t(k * (c + 1));
  }
  os << "      <Points>\n";
  write_data_array(os, "Float64", "Points", 3, row_major(points), enc, in);
  os << "      </Points>\n"
     << "      <Cells>\n";
  write_data_array(os, "Int64", "connectivity", 1, connectivity, enc, in);
  write_data_array(os, "Int64", "offsets", 1, offsets, enc, in);
  write_data_array(os, "UInt8", "types", 1, types, enc, in);
  os << "      </Cells>\n"
     << "    </Piece>\n"
     << "  </UnstructuredGrid>\n"
     << "</VTKFile>\n";
}

void check_arrays(const std::string& path, const std::vector<DataArray>& arrays, Eigen::Index rows,
                  const char* kind, const std::vector<std::string>& reserved) {
  for (const DataArray& a : arrays) {
    const std::string head = "write_vtu: " + path + ": " + kind + " array '" + a.name + "'";
    if (a.name.empty())
      throw std::invalid_argument("write_vtu: " + path + ": a " + kind + " array has no name");
    if (std::find(reserved.begin(), reserved.end(), a.name) != reserved.end())
      throw std::invalid_argument(head + " uses a reserved name (written from the mesh itself)");
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

using detail::RawArray;

/// How the binary arrays of a file are compressed (VTKFile compressor=…).
enum class Compressor { none, zlib, lzma, lz4 };

struct Reader : detail::FileError {
  bool swap_bytes = false;
  int header_bytes = 4;  // UInt32 by default (VTK XML format 0.1 and 1.0)
  Compressor compressor = Compressor::none;
  // <AppendedData>: the bytes after its '_' marker (raw bytes, or base64 text), and the sorted
  // offsets of every appended array (a base64 array ends where the next one starts).
  bool has_appended = false, appended_base64 = false;
  std::string appended;
  std::vector<std::int64_t> appended_offsets;
};

struct VtkType {
  int size;
  char kind;  // 'i' signed, 'u' unsigned, 'f' float
};

bool vtk_type(const std::string& t, VtkType& out) {
  static const struct {
    const char* name;
    VtkType type;
  } table[] = {
      {"Int8", {1, 'i'}},    {"UInt8", {1, 'u'}},   {"Int16", {2, 'i'}},  {"UInt16", {2, 'u'}},
      {"Int32", {4, 'i'}},   {"UInt32", {4, 'u'}},  {"Int64", {8, 'i'}},  {"UInt64", {8, 'u'}},
      {"Float32", {4, 'f'}}, {"Float64", {8, 'f'}}, {"String", {1, 'u'}}, {"Char", {1, 'i'}},
  };
  for (const auto& e : table)
    if (t == e.name) {
      out = e.type;
      return true;
    }
  return false;
}

/// A count or offset attribute: decimal digits only (tinyxml2 alone reads "7.5e2" as 7).
tinyxml2::XMLError count_attribute(const tinyxml2::XMLElement* e, const char* name,
                                   std::int64_t* value) {
  const char* text = e->Attribute(name);
  if (!text) return tinyxml2::XML_NO_ATTRIBUTE;
  std::string t(text);
  while (!t.empty() && (t.back() == ' ' || t.back() == '\t')) t.pop_back();
  std::size_t start = t.find_first_not_of(" \t");
  if (start == std::string::npos || t.size() - start > 18)
    return tinyxml2::XML_WRONG_ATTRIBUTE_TYPE;
  t = t.substr(start);
  if (!std::all_of(t.begin(), t.end(), [](char c) { return c >= '0' && c <= '9'; }))
    return tinyxml2::XML_WRONG_ATTRIBUTE_TYPE;
  *value = std::stoll(t);
  return tinyxml2::XML_SUCCESS;
}

/// The value of type T stored (native byte order) at `b`.
template <class T>
T load(const unsigned char* b) {
  T x;
  std::memcpy(&x, b, sizeof x);
  return x;
}

double decode_value(const unsigned char* p, VtkType t, bool swap) {
  unsigned char b[8];
  const std::size_t n = std::min<std::size_t>(std::size_t(t.size), sizeof b);  // 1, 2, 4 or 8
  std::memcpy(b, p, n);
  if (swap) std::reverse(b, b + n);
  switch (t.kind) {
    case 'f':
      return t.size == 4 ? double(load<float>(b)) : load<double>(b);
    case 'i':
      switch (t.size) {
        case 1:
          return double(load<std::int8_t>(b));
        case 2:
          return double(load<std::int16_t>(b));
        case 4:
          return double(load<std::int32_t>(b));
        case 8:
          return double(load<std::int64_t>(b));
        default:
          return 0.0;
      }
    default:
      switch (t.size) {
        case 1:
          return double(load<std::uint8_t>(b));
        case 2:
          return double(load<std::uint16_t>(b));
        case 4:
          return double(load<std::uint32_t>(b));
        case 8:
          return double(load<std::uint64_t>(b));
        default:
          return 0.0;
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
    if (res.ec != std::errc() ||
        (res.ptr < end && !std::isspace(static_cast<unsigned char>(*res.ptr)))) {
      const char* tok_end = s;
      while (tok_end < end && tok_end - s < 24 &&
             !std::isspace(static_cast<unsigned char>(*tok_end)))
        ++tok_end;
      r.fail("DataArray '" + name + "' has a value that is not a number: \"" +
             std::string(s, tok_end) + "\"");
    }
    v.push_back(x);
    s = res.ptr;
  }
  return v;
}

/// The largest uncompressed array a file may announce: a guard against a corrupt or hostile
/// header making the reader allocate without bound (a 10M-tet mesh's connectivity is 320 MB).
constexpr std::uint64_t kMaxArrayBytes = std::uint64_t(4) << 30;

std::uint64_t header_value(const Reader& r, const unsigned char* p) {
  return std::uint64_t(decode_value(p, VtkType{r.header_bytes, 'u'}, r.swap_bytes));
}

/// Decompresses one block of `csize` bytes at `src` into exactly `usize` bytes at `dst`.
void inflate_block(const Reader& r, const std::string& name, const unsigned char* src,
                   std::uint64_t csize, unsigned char* dst, std::uint64_t usize) {
  bool ok = false;
  if (r.compressor == Compressor::zlib) {
    uLongf dlen = uLongf(usize);
    ok = ::uncompress(dst, &dlen, src, uLong(csize)) == Z_OK && dlen == usize;
  } else if (r.compressor == Compressor::lz4) {
    // VTK's LZ4 compressor stores raw LZ4 blocks (no frame), one per VTK block.
    ok = csize <= std::uint64_t(std::numeric_limits<int>::max()) &&
         usize <= std::uint64_t(std::numeric_limits<int>::max()) &&
         LZ4_decompress_safe(reinterpret_cast<const char*>(src), reinterpret_cast<char*>(dst),
                             int(csize), int(usize)) == int(usize);
  } else {
    lzma_stream z = LZMA_STREAM_INIT;
    if (lzma_auto_decoder(&z, UINT64_MAX, 0) == LZMA_OK) {
      z.next_in = src, z.avail_in = std::size_t(csize);
      z.next_out = dst, z.avail_out = std::size_t(usize);
      const lzma_ret rc = lzma_code(&z, LZMA_FINISH);
      ok = (rc == LZMA_STREAM_END || rc == LZMA_OK) && z.avail_out == 0;
      lzma_end(&z);
    }
  }
  if (!ok)
    r.fail("DataArray '" + name + "' has a compressed block that does not decompress to its " +
           std::to_string(usize) + " bytes (corrupt data)");
}

/// The payload of one binary array stored at `p` (`n` bytes available): VTK's header — the byte
/// count, or with a compressor [#blocks, block size, last block size, compressed sizes…], each
/// of header_type — then the data, decompressed.
std::vector<unsigned char> read_block(const Reader& r, const std::string& name,
                                      const unsigned char* p, std::size_t n) {
  const std::size_t hb = std::size_t(r.header_bytes);
  const auto truncated = [&](const std::string& what) {
    r.fail("DataArray '" + name + "' binary data is truncated (" + what + ")");
  };
  if (r.compressor == Compressor::none) {
    if (n < hb) truncated("no block header");
    const std::uint64_t nbytes = header_value(r, p);
    if (n - hb < nbytes)
      truncated("header says " + std::to_string(nbytes) + " bytes, found " +
                std::to_string(n - hb));
    return std::vector<unsigned char>(p + hb, p + hb + nbytes);
  }
  if (n < 3 * hb) truncated("no compression header");
  const std::uint64_t nblocks = header_value(r, p), block = header_value(r, p + hb),
                      last = header_value(r, p + 2 * hb);
  if (nblocks > n / hb - 3)
    truncated("the compression header counts " + std::to_string(nblocks) + " blocks");
  if (nblocks > 0 && (block == 0 || last > block))
    r.fail("DataArray '" + name + "' has an inconsistent compression header (block size " +
           std::to_string(block) + ", last block " + std::to_string(last) + ")");
  const std::uint64_t total = nblocks == 0 ? 0 : (nblocks - 1) * block + (last > 0 ? last : block);
  if (block > kMaxArrayBytes || total > kMaxArrayBytes)
    r.fail("DataArray '" + name + "' announces " + std::to_string(total) +
           " uncompressed bytes, more than a mesh array may hold (4 GiB)");
  std::vector<unsigned char> out(static_cast<std::size_t>(total));
  const unsigned char* data = p + (3 + nblocks) * hb;
  std::size_t avail = n - std::size_t(3 + nblocks) * hb, pos = 0;
  for (std::uint64_t k = 0; k < nblocks; ++k) {
    const std::uint64_t csize = header_value(r, p + (3 + k) * hb);
    if (csize > avail) truncated("block " + std::to_string(k) + " of " + std::to_string(nblocks));
    const std::uint64_t usize = (k + 1 == nblocks && last > 0) ? last : block;
    inflate_block(r, name, data, csize, out.data() + pos, usize);
    data += csize, avail -= std::size_t(csize), pos += std::size_t(usize);
  }
  return out;
}

std::vector<double> to_values(const Reader& r, const std::string& name,
                              const std::vector<unsigned char>& bytes, VtkType t) {
  if (bytes.size() % std::size_t(t.size) != 0)
    r.fail("DataArray '" + name + "' byte count " + std::to_string(bytes.size()) +
           " is not a multiple of the value size");
  std::vector<double> v(bytes.size() / std::size_t(t.size));
  for (std::size_t i = 0; i < v.size(); ++i)
    v[i] = decode_value(bytes.data() + i * std::size_t(t.size), t, r.swap_bytes);
  return v;
}

std::vector<unsigned char> decode_base64(const Reader& r, const std::string& name, const char* text,
                                         std::size_t n) {
  std::vector<unsigned char> bytes;
  if (!text || !base64_decode(text, n, bytes))
    r.fail("DataArray '" + name + "' has invalid or truncated base64 data");
  return bytes;
}

/// An array in <AppendedData> at `offset` (bytes into the raw data, or characters into the
/// base64 text, after the '_' marker).
std::vector<unsigned char> appended_block(const Reader& r, const std::string& name,
                                          std::int64_t offset) {
  if (!r.has_appended)
    r.fail("DataArray '" + name + "' is appended but the file has no <AppendedData>");
  if (offset < 0 || std::size_t(offset) >= r.appended.size())
    r.fail("DataArray '" + name + "' offset " + std::to_string(offset) +
           " is outside the appended data (" + std::to_string(r.appended.size()) + " bytes)");
  if (!r.appended_base64) {
    const auto* p = reinterpret_cast<const unsigned char*>(r.appended.data()) + offset;
    return read_block(r, name, p, r.appended.size() - std::size_t(offset));
  }
  auto next = std::upper_bound(r.appended_offsets.begin(), r.appended_offsets.end(), offset);
  const std::size_t end = next == r.appended_offsets.end() ? r.appended.size() : std::size_t(*next);
  const auto bytes = decode_base64(r, name, r.appended.data() + offset, end - std::size_t(offset));
  return read_block(r, name, bytes.data(), bytes.size());
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
    const char* text = da->GetText();
    const auto bytes = decode_base64(r, label, text, text ? std::strlen(text) : 0);
    a.v = to_values(r, label, read_block(r, label, bytes.data(), bytes.size()), t);
  } else if (format == "appended") {
    std::int64_t offset = -1;
    if (count_attribute(da, "offset", &offset) != tinyxml2::XML_SUCCESS)
      r.fail("DataArray '" + label + "' is appended but has no offset");
    a.v = to_values(r, label, appended_block(r, label, offset), t);
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
  for (auto* da = parent->FirstChildElement("DataArray"); da;
       da = da->NextSiblingElement("DataArray"))
    out.push_back(read_array(r, da));
  return out;
}

const tinyxml2::XMLElement* find_named(const tinyxml2::XMLElement* parent, const char* name) {
  if (!parent) return nullptr;
  for (auto* da = parent->FirstChildElement("DataArray"); da;
       da = da->NextSiblingElement("DataArray")) {
    const char* n = da->Attribute("Name");
    if (n && std::strcmp(n, name) == 0) return da;
  }
  return nullptr;
}

/// The file's text with the raw or base64 payload of <AppendedData> cut out (into r.appended):
/// raw bytes are not XML, so the XML parser sees `<AppendedData …>_</AppendedData>`.
std::string split_appended(Reader& r, std::string text) {
  const std::size_t open = text.find("<AppendedData");
  if (open == std::string::npos) return text;
  const std::size_t tag_end = text.find('>', open);
  const std::size_t close = text.rfind("</AppendedData>");
  if (tag_end == std::string::npos || close == std::string::npos || close < tag_end)
    r.fail("<AppendedData> is not closed (truncated file?)");
  const std::string tag = text.substr(open, tag_end - open);
  const std::size_t enc = tag.find("encoding=\"");
  const std::string encoding =
      enc == std::string::npos ? "raw" : tag.substr(enc + 10, tag.find('"', enc + 10) - enc - 10);
  if (encoding != "raw" && encoding != "base64")
    r.fail("<AppendedData> has unknown encoding '" + encoding + "' (raw or base64)");
  const std::size_t marker = text.find('_', tag_end);
  if (marker == std::string::npos || marker > close)
    r.fail("<AppendedData> has no '_' marker before its data");
  r.has_appended = true;
  r.appended_base64 = encoding == "base64";
  r.appended = text.substr(marker + 1, close - marker - 1);
  return text.substr(0, marker + 1) + text.substr(close);
}

/// Byte order, header size and compressor from <VTKFile>.
void read_envelope(Reader& r, const tinyxml2::XMLElement* root) {
  const char* ftype = root->Attribute("type");
  if (!ftype || std::strcmp(ftype, "UnstructuredGrid") != 0)
    r.fail(std::string("not an UnstructuredGrid (VTKFile type=\"") + (ftype ? ftype : "") + "\")");
  if (const char* comp = root->Attribute("compressor")) {
    if (std::strcmp(comp, "vtkZLibDataCompressor") == 0)
      r.compressor = Compressor::zlib;
    else if (std::strcmp(comp, "vtkLZMADataCompressor") == 0)
      r.compressor = Compressor::lzma;
    else if (std::strcmp(comp, "vtkLZ4DataCompressor") == 0)
      r.compressor = Compressor::lz4;
    else
      r.fail(std::string("data compressed with ") + comp +
             ", which is not supported; re-save it with zlib, LZ4 or LZMA compression, or "
             "uncompressed (ParaView: Compressor Type ZLib, LZ4, LZMA or None)");
  }
  const char* order = root->Attribute("byte_order");
  const bool file_little = !order || std::strcmp(order, "BigEndian") != 0;
  r.swap_bytes = file_little != host_is_little_endian();
  if (const char* ht = root->Attribute("header_type")) {
    if (std::strcmp(ht, "UInt32") == 0)
      r.header_bytes = 4;
    else if (std::strcmp(ht, "UInt64") == 0)
      r.header_bytes = 8;
    else
      r.fail(std::string("unsupported header_type \"") + ht + "\"");
  }
}

/// The offsets of every appended DataArray below `e`, sorted (r.appended_offsets).
void collect_offsets(Reader& r, const tinyxml2::XMLElement* e) {
  for (const auto* c = e->FirstChildElement(); c; c = c->NextSiblingElement()) {
    std::int64_t off = 0;
    if (std::strcmp(c->Name(), "DataArray") == 0 &&
        count_attribute(c, "offset", &off) == tinyxml2::XML_SUCCESS)
      r.appended_offsets.push_back(off);
    collect_offsets(r, c);
  }
}

}  // namespace

/// The run's provenance (common/provenance.hpp) as the FieldData array "provenance": the JSON
/// text's bytes, UInt8, like "source" (numpy: bytes(array).decode()). Nothing outside a recorded
/// run.
std::vector<std::uint8_t> provenance_bytes() {
  const nlohmann::json p = run_provenance();
  if (p.is_null()) return {};
  const std::string text = p.dump();
  return std::vector<std::uint8_t>(text.begin(), text.end());
}

// ==========================================================================================

void write_vtu(const std::string& path, const TetMesh& m, const std::vector<DataArray>& point_data,
               const std::vector<DataArray>& cell_data, const VtuWriteOptions& options) {
  // 1. Refuse bad input before touching the disk.
  const std::string who = "write_vtu: " + path + ": ";
  detail::check_mesh_for_writing(m, who);
  if (!m.frame.origin_mm.allFinite() || !m.frame.axes.allFinite())
    throw std::invalid_argument(who + "disc frame contains non-finite values");
  check_arrays(path, point_data, m.num_vertices(), "point", {"surface"});
  check_arrays(path, cell_data, m.num_tets(), "cell",
               {"region", kFibrePathArray[0], kFibrePathArray[1]});
  try {
    validate_fibre_paths(m);
  } catch (const std::invalid_argument& ex) {
    throw std::invalid_argument(who + ex.what());
  }
  std::vector<DataArray> paths;  // the mesh's own fibre directions, after `region`
  if (!m.fibre_paths.empty())
    paths = {{kFibrePathArray[0], m.fibre_paths.direction_1},
             {kFibrePathArray[1], m.fibre_paths.direction_2}};
  if (!host_is_little_endian())
    throw std::runtime_error(who + "writing VTU on a big-endian host is not implemented");

  // 2. Flatten the labels and the frame.
  const std::size_t nt = std::size_t(m.num_tets());
  const std::vector<std::int32_t> region(m.region.data(), m.region.data() + m.region.size());
  const std::vector<std::int32_t> surface(m.surface.data(), m.surface.data() + m.surface.size());
  std::vector<double> frame(12);
  for (int i = 0; i < 3; ++i) frame[std::size_t(i)] = m.frame.origin_mm(i);
  for (int c = 0; c < 3; ++c)
    for (int i = 0; i < 3; ++i) frame[std::size_t(3 + 3 * c + i)] = m.frame.axes(i, c);
  const std::vector<std::uint8_t> source(m.source.begin(), m.source.end());
  const VtuEncoding enc = options.encoding;
  const std::vector<std::uint8_t> provenance = provenance_bytes();

  // 3. Write to a temporary file, then rename.
  write_atomically("write_vtu", path, [&](std::ostream& os) {
    os << "<?xml version=\"1.0\"?>\n"
       << "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" "
          "header_type=\"UInt64\""
       << (enc == VtuEncoding::zlib ? " compressor=\"vtkZLibDataCompressor\"" : "") << ">\n"
       << "  <UnstructuredGrid>\n"
       << "    <FieldData>\n";
    write_data_array(os, "Float64", "disc_frame", 12, frame, VtuEncoding::ascii, "      ",
                     Tuples::stated);
    if (!source.empty())
      write_data_array(os, "UInt8", "source", 1, source, VtuEncoding::ascii, "      ",
                       Tuples::stated);
    if (!provenance.empty())
      write_data_array(os, "UInt8", "provenance", 1, provenance, enc, "      ", Tuples::stated);
    os << "    </FieldData>\n"
       << "    <Piece NumberOfPoints=\"" << m.num_vertices() << "\" NumberOfCells=\"" << nt
       << "\">\n"
       << "      <PointData Scalars=\"surface\">\n";
    const char* in = "        ";
    write_data_array(os, "Int32", "surface", 1, surface, enc, in);
    write_extra_arrays(os, point_data, enc, in);
    os << "      </PointData>\n"
       << "      <CellData Scalars=\"region\">\n";
    write_data_array(os, "Int32", "region", 1, region, enc, in);
    write_extra_arrays(os, paths, enc, in);
    write_extra_arrays(os, cell_data, enc, in);
    os << "      </CellData>\n";
    write_points_cells_and_close(os, m.V, m.T, 10, enc);  // VTK_TETRA
  });
}

void write_surface_vtu(const std::string& path, const TriSurface& s,
                       const std::vector<DataArray>& point_data,
                       const std::vector<DataArray>& cell_data, const VtuWriteOptions& options) {
  const std::string who = "write_vtu: " + path + ": ";
  if (s.V.rows() == 0 || s.F.rows() == 0)
    throw std::invalid_argument(who + "surface is empty (no vertices or no triangles)");
  if (!s.V.allFinite())
    throw std::invalid_argument(who + "vertex coordinates contain non-finite values");
  if (s.F.minCoeff() < 0 || s.F.maxCoeff() >= s.V.rows())
    throw std::invalid_argument(who + "a triangle has a vertex index out of range");
  check_arrays(path, point_data, s.V.rows(), "point", {});
  check_arrays(path, cell_data, s.F.rows(), "cell", {});
  if (!host_is_little_endian())
    throw std::runtime_error(who + "writing VTU on a big-endian host is not implemented");

  const std::size_t nf = std::size_t(s.F.rows());
  const VtuEncoding enc = options.encoding;
  const std::vector<std::uint8_t> provenance = provenance_bytes();
  write_atomically("write_vtu", path, [&](std::ostream& os) {
    const char* in = "        ";
    os << "<?xml version=\"1.0\"?>\n"
       << "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" "
          "header_type=\"UInt64\""
       << (enc == VtuEncoding::zlib ? " compressor=\"vtkZLibDataCompressor\"" : "") << ">\n"
       << "  <UnstructuredGrid>\n";
    if (!provenance.empty()) {
      os << "    <FieldData>\n";
      write_data_array(os, "UInt8", "provenance", 1, provenance, enc, "      ", Tuples::stated);
      os << "    </FieldData>\n";
    }
    os << "    <Piece NumberOfPoints=\"" << s.V.rows() << "\" NumberOfCells=\"" << nf << "\">\n"
       << "      <PointData>\n";
    write_extra_arrays(os, point_data, enc, in);
    os << "      </PointData>\n"
       << "      <CellData>\n";
    write_extra_arrays(os, cell_data, enc, in);
    os << "      </CellData>\n";
    write_points_cells_and_close(os, s.V, s.F, 5, enc);  // VTK_TRIANGLE
  });
}

// ==========================================================================================

namespace {

/// Steps 1-2 of every VTU reader: the file, its XML envelope and the grid's arrays, decoded.
detail::RawGrid read_raw_vtu(Reader& r, const std::string& path) {
  using tinyxml2::XMLElement;
  // 1. File and XML envelope; the appended payload is cut out before XML parsing.
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec))
    r.fail(path_kind(path).empty() ? "no such file"
                                   : "it is " + path_kind(path) + ", not a regular file");
  std::ifstream in(path, std::ios::binary);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (!in && !in.eof()) r.fail("cannot read the file");
  record_input_file(path);
  text = split_appended(r, std::move(text));
  tinyxml2::XMLDocument doc;
  if (doc.Parse(text.data(), text.size()) != tinyxml2::XML_SUCCESS) {
    std::string err = doc.ErrorStr() ? doc.ErrorStr() : "unknown error";
    std::replace(err.begin(), err.end(), '\n', ' ');
    r.fail("not a readable XML file (" + err + ")");
  }
  const XMLElement* root = doc.RootElement();
  if (!root || std::strcmp(root->Name(), "VTKFile") != 0)
    r.fail("not a VTK XML file (no <VTKFile>)");
  read_envelope(r, root);
  collect_offsets(r, root);
  std::sort(r.appended_offsets.begin(), r.appended_offsets.end());
  const XMLElement* grid = root->FirstChildElement("UnstructuredGrid");
  if (!grid) r.fail("no <UnstructuredGrid> element");
  const XMLElement* piece = grid->FirstChildElement("Piece");
  if (!piece) r.fail("no <Piece> element");
  if (piece->NextSiblingElement("Piece"))
    r.fail("has more than one Piece; merge them into one first");

  // 2. The grid's arrays, decoded.
  detail::RawGrid g;
  if (count_attribute(piece, "NumberOfPoints", &g.num_points) != tinyxml2::XML_SUCCESS ||
      g.num_points < 0)
    r.fail("Piece has no valid NumberOfPoints");
  if (count_attribute(piece, "NumberOfCells", &g.num_cells) != tinyxml2::XML_SUCCESS ||
      g.num_cells < 0)
    r.fail("Piece has no valid NumberOfCells");
  if (g.num_points == 0 || g.num_cells == 0)
    r.fail("mesh is empty (NumberOfPoints or NumberOfCells is 0)");
  const XMLElement* points_el = piece->FirstChildElement("Points");
  const XMLElement* pda = points_el ? points_el->FirstChildElement("DataArray") : nullptr;
  if (!pda) r.fail("no <Points> DataArray");
  g.points = read_array(r, pda);
  const XMLElement* cells_el = piece->FirstChildElement("Cells");
  if (!cells_el) r.fail("no <Cells> element");
  auto cell_array = [&](const char* name, double hi) {
    const XMLElement* da = find_named(cells_el, name);
    if (!da) r.fail(std::string("Cells has no '") + name + "' DataArray");
    RawArray a = read_array(r, da);
    a.name = name;
    return detail::as_integers(r, a, 0, hi);
  };
  g.connectivity = cell_array("connectivity", double(g.num_points - 1));
  g.offsets = cell_array("offsets", 9e15);
  g.types = cell_array("types", 255);
  g.point_data = read_arrays(r, piece->FirstChildElement("PointData"));
  g.cell_data = read_arrays(r, piece->FirstChildElement("CellData"));
  const XMLElement* field =
      grid->FirstChildElement("FieldData");  // other field arrays are not decoded
  if (const XMLElement* da = find_named(field, "disc_frame")) g.disc_frame = read_array(r, da);
  if (const XMLElement* da = find_named(field, "source")) g.source = read_array(r, da);
  return g;
}

}  // namespace

TetMesh read_vtu(const std::string& path, std::vector<DataArray>* point_data,
                 std::vector<DataArray>* cell_data) {
  Reader r;
  r.who = "read_vtu";
  r.path = path;
  detail::RawGrid g = read_raw_vtu(r, path);
  // 3. The mesh, checked (vtk_grid.cpp).
  return detail::assemble_tet_mesh(r, std::move(g), point_data, cell_data);
}

VtuGrid read_vtu_grid(const std::string& path) {
  Reader r;
  r.who = "read_vtu";
  r.path = path;
  return detail::assemble_grid(r, read_raw_vtu(r, path));
}

}  // namespace spinesim::mesh
