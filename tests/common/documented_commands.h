// SPDX-License-Identifier: LGPL-2.1-or-later
// The project's documents as tests read them: tests run the commands that README.md and docs/
// tell users to run, as written, so each document's sections and commands are found here, by
// one rule. Needs PFAP_SOURCE_DIR, the source tree's root (a -D of the test).
#pragma once

#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace pfap::testing {

// A file of the source tree, from its path relative to the root.
inline std::string source_path(const std::string& relative) {
  return std::string(PFAP_SOURCE_DIR) + "/" + relative;
}

// A file's whole text; empty if it cannot be read.
inline std::string read_file(const std::string& path) {
  std::ifstream file(path, std::ios::binary);
  std::ostringstream text;
  text << file.rdbuf();
  return text.str();
}

inline std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

inline void replace_all(std::string& s, const std::string& from, const std::string& to) {
  for (size_t at = s.find(from); at != std::string::npos; at = s.find(from, at + to.size())) {
    s.replace(at, from.size(), to);
  }
}

// The Markdown heading level of `line` (2 for "## x"), 0 if it is not a heading.
inline size_t heading_level(const std::string& line) {
  const size_t hashes = line.find_first_not_of('#');
  return hashes > 0 && hashes != std::string::npos && line[hashes] == ' ' ? hashes : 0;
}

// The lines under `heading` (a whole line such as "## pfapface"), up to the next heading of
// its level or a higher one; a '#' line inside a fenced block is no heading. Empty if `lines`
// has no such heading.
inline std::vector<std::string> section(const std::vector<std::string>& lines,
                                        const std::string& heading) {
  const size_t level = heading_level(heading);
  std::vector<std::string> out;
  bool inside = false, in_block = false;
  for (const std::string& line : lines) {
    if (line.starts_with("```")) in_block = !in_block;
    const size_t l = in_block || line.starts_with("```") ? 0 : heading_level(line);
    if (l > 0 && l <= level) {
      if (inside) break;
      inside = line == heading;
      continue;
    }
    if (inside) out.push_back(line);
  }
  return out;
}

// The section under `heading` of a document of the source tree ("docs/elements.md").
inline std::vector<std::string> doc_section(const std::string& file, const std::string& heading) {
  return section(lines_of(read_file(source_path(file))), heading);
}

// The commands in the fenced blocks of `lines`: comment lines and trailing " # ..." comments
// dropped, a line ending in '\' joined with the next, a trailing '&' (run in the background)
// dropped.
inline std::vector<std::string> commands_in(const std::vector<std::string>& lines) {
  std::vector<std::string> commands;
  bool in_block = false, continued = false;
  for (const std::string& line : lines) {
    if (line.starts_with("```")) {
      in_block = !in_block;
      continue;
    }
    if (!in_block || (!continued && line.starts_with('#'))) continue;
    std::string part = line.substr(0, line.find(" #"));
    const bool continues = part.ends_with('\\');
    if (continues) part.pop_back();
    if (continued) {
      commands.back() += " " + part.substr(std::min(part.find_first_not_of(' '), part.size()));
    } else {
      commands.push_back(part);
    }
    continued = continues;
  }
  for (std::string& c : commands) {
    while (!c.empty() && (c.back() == ' ' || c.back() == '&')) c.pop_back();
  }
  std::erase_if(commands, [](const std::string& c) { return c.empty(); });
  return commands;
}

// A gst-launch-1.0 command's pipeline description ("gst-launch-1.0 [-e] DESCRIPTION"), or ""
// if `command` is not one.
inline std::string launch_description(const std::string& command) {
  const std::string program = "gst-launch-1.0 ";
  if (!command.starts_with(program)) return "";
  std::string description = command.substr(program.size());
  if (description.starts_with("-e ")) description = description.substr(3);
  return description;
}

// The pipeline descriptions of the gst-launch-1.0 commands in the fenced blocks of `lines`.
inline std::vector<std::string> launch_descriptions(const std::vector<std::string>& lines) {
  std::vector<std::string> descriptions;
  for (const std::string& command : commands_in(lines)) {
    if (std::string d = launch_description(command); !d.empty()) descriptions.push_back(d);
  }
  return descriptions;
}

}  // namespace pfap::testing
