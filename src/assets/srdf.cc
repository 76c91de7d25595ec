// SRDF reading: <disable_collisions> pairs.
#include "partsim/assets/srdf.h"

#include <tinyxml2.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "core/file_read.h"
#include "partsim/core/error.h"

namespace partsim {

SrdfDesc ParseSrdf(const std::string& text, const std::string& source, LoadReport* report) {
  auto fail = [&](const std::string& what) { throw Error("SRDF " + source + ": " + what); };
  tinyxml2::XMLDocument doc;
  if (doc.Parse(text.data(), text.size()) != tinyxml2::XML_SUCCESS)
    fail("malformed XML at line " + std::to_string(doc.ErrorLineNum()) + ": " +
         (doc.ErrorStr() ? doc.ErrorStr() : "unknown error"));
  const tinyxml2::XMLElement* robot = doc.RootElement();
  if (robot == nullptr || std::string(robot->Name()) != "robot")
    fail("the root element must be <robot>" +
         (robot ? " (line " + std::to_string(robot->GetLineNum()) + " has <" + robot->Name() + ">)"
                : std::string()));
  SrdfDesc out;
  if (const char* name = robot->Attribute("name")) out.robot_name = name;
  for (const tinyxml2::XMLElement* e = robot->FirstChildElement("disable_collisions"); e;
       e = e->NextSiblingElement("disable_collisions")) {
    SrdfDisabledCollision pair;
    const char* link1 = e->Attribute("link1");
    const char* link2 = e->Attribute("link2");
    pair.line = e->GetLineNum();
    if (link1 == nullptr || link2 == nullptr) {
      if (report)
        report->Warn(source, "<disable_collisions> at line " + std::to_string(pair.line) +
                                 " lacks link1 or link2; skipped");
      continue;
    }
    pair.link1 = link1;
    pair.link2 = link2;
    if (const char* reason = e->Attribute("reason")) pair.reason = reason;
    out.disabled_collisions.push_back(std::move(pair));
  }
  return out;
}

SrdfDesc ReadSrdfFile(const std::string& path, LoadReport* report) {
  return ParseSrdf(internal::ReadWholeFile(path, "SRDF"), path, report);
}

}  // namespace partsim
