// ParaView data collection (.pvd): the index of a VTU time series. Format (VTK file formats,
// "Collection" / ParaView Data):
//   <VTKFile type="Collection" version="0.1" byte_order="LittleEndian">
//     <Collection>
//       <DataSet timestep="0.001" group="" part="0" file="series/frame_000001.vtu"/>
//     </Collection>
//   </VTKFile>
#include "spinesim/mesh/io.hpp"

#include "spinesim/common/atomic_file.hpp"
#include "spinesim/common/provenance.hpp"
#include "xml_escape.hpp"

#include <tinyxml2.h>

#include <charconv>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <stdexcept>

namespace spinesim::mesh {
namespace {

std::string shortest(double v) {
  char buf[64];
  const auto res = std::to_chars(buf, buf + sizeof buf, v);  // shortest round-trip form
  return std::string(buf, res.ptr);
}

}  // namespace

void write_pvd(const std::string& path, const std::vector<PvdEntry>& entries) {
  // 1. Refuse bad input before touching the disk.
  const std::string who = "write_pvd: " + path + ": ";
  if (entries.empty()) throw std::invalid_argument(who + "no datasets to list");
  std::map<int, double> last_time;  // per part
  for (std::size_t i = 0; i < entries.size(); ++i) {
    const PvdEntry& e = entries[i];
    const std::string which = "dataset " + std::to_string(i);
    if (e.part < 0) throw std::invalid_argument(who + which + " has a negative part");
    if (!std::isfinite(e.time_s))
      throw std::invalid_argument(who + which + " has a non-finite time");
    const auto last = last_time.find(e.part);
    if (last != last_time.end() && !(e.time_s > last->second))
      throw std::invalid_argument(who + which + ": times must be strictly increasing (" +
                                  shortest(last->second) + " then " + shortest(e.time_s) + ")");
    last_time[e.part] = e.time_s;
    if (e.file.empty()) throw std::invalid_argument(who + which + " has an empty file name");
    for (char c : e.file)
      if (static_cast<unsigned char>(c) < 0x20)
        throw std::invalid_argument(who + which + ": control character in the file name");
  }

  // 2. Write to a temporary file, then rename.
  write_atomically("write_pvd", path, [&](std::ostream& os) {
    os << "<?xml version=\"1.0\"?>\n"
       << "<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
       << "  <Collection>\n";
    for (const PvdEntry& e : entries)
      os << "    <DataSet timestep=\"" << shortest(e.time_s) << "\" group=\"\" part=\"" << e.part
         << "\" file=\"" << detail::xml_escape(e.file) << "\"/>\n";
    os << "  </Collection>\n"
       << "</VTKFile>\n";
  });
}

const DataArray* VtuGrid::point_array(const std::string& name) const {
  for (const DataArray& a : point_data)
    if (a.name == name) return &a;
  return nullptr;
}

const DataArray* VtuGrid::cell_array(const std::string& name) const {
  for (const DataArray& a : cell_data)
    if (a.name == name) return &a;
  return nullptr;
}

std::vector<PvdEntry> read_pvd(const std::string& path) {
  const std::string who = "read_pvd: " + path + ": ";
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec))
    throw std::invalid_argument(who + "no such file");
  tinyxml2::XMLDocument doc;
  if (doc.LoadFile(path.c_str()) != tinyxml2::XML_SUCCESS)
    throw std::invalid_argument(who + "not a readable XML file");
  record_input_file(path);
  const tinyxml2::XMLElement* root = doc.RootElement();
  const char* type = root ? root->Attribute("type") : nullptr;
  if (!root || std::string(root->Name()) != "VTKFile" || !type || std::string(type) != "Collection")
    throw std::invalid_argument(who + "not a ParaView collection (VTKFile type=\"Collection\")");
  const tinyxml2::XMLElement* coll = root->FirstChildElement("Collection");
  std::vector<PvdEntry> out;
  std::map<int, double> last_time;
  const std::filesystem::path folder = std::filesystem::path(path).parent_path();
  for (const tinyxml2::XMLElement* d = coll ? coll->FirstChildElement("DataSet") : nullptr; d;
       d = d->NextSiblingElement("DataSet")) {
    const std::string which = "DataSet " + std::to_string(out.size());
    PvdEntry e;
    const char* t = d->Attribute("timestep");
    char* end = nullptr;
    e.time_s = t ? std::strtod(t, &end) : 0;
    if (t && (end == t || *end != '\0' || !std::isfinite(e.time_s)))
      throw std::invalid_argument(who + which + ": timestep is not a finite number");
    if (d->QueryIntAttribute("part", &e.part) == tinyxml2::XML_WRONG_ATTRIBUTE_TYPE || e.part < 0)
      throw std::invalid_argument(who + which + ": part must be a non-negative integer");
    const char* f = d->Attribute("file");
    if (!f || !*f) throw std::invalid_argument(who + which + " has no file");
    const std::filesystem::path file(f);
    e.file = file.is_absolute() ? file.string() : (folder / file).string();
    const auto last = last_time.find(e.part);
    if (last != last_time.end() && !(e.time_s > last->second))
      throw std::invalid_argument(who + which + ": times must be strictly increasing per part");
    last_time[e.part] = e.time_s;
    out.push_back(e);
  }
  if (out.empty()) throw std::invalid_argument(who + "lists no datasets");
  return out;
}

}  // namespace spinesim::mesh
