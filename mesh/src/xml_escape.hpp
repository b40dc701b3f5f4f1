// XML attribute/text escaping for the VTK XML writers (VTU, PVD). Private to spinesim::mesh.
#pragma once

#include <string>

namespace spinesim::mesh::detail {

inline std::string xml_escape(const std::string& s) {
  std::string r;
  for (char c : s) {
    switch (c) {
      case '&':
        r += "&amp;";
        break;
      case '<':
        r += "&lt;";
        break;
      case '>':
        r += "&gt;";
        break;
      case '"':
        r += "&quot;";
        break;
      case '\'':
        r += "&apos;";
        break;
      default:
        r += c;
    }
  }
  return r;
}

}  // namespace spinesim::mesh::detail
