// The generator's two vocabularies of links, as in the real dataset: the semantics.txt label
// (the movable-part vocabulary of the SAPIEN paper's tables, used by tasks and benchmarks) and
// the mobility_v2.json name (PartNet's part names). Category builders name links with a key;
// the tables below turn (category, key) into both.
#include <cstring>
#include <string>

#include "assets/generator/categories.h"
#include "partsim/core/error.h"

namespace partsim::internal::gen {
namespace {

/// The body of each category (the link joined to base): semantics label, PartNet name.
struct BodyLabel {
  const char* category;
  const char* label;
  const char* partnet;
};

const BodyLabel kBodies[] = {
    {"Bottle", "bottle_body", "body"},
    {"Box", "box_body", "body"},
    {"Bucket", "bucket_body", "body"},
    {"StorageFurniture", "furniture_body", "cabinet_frame"},
    {"Camera", "camera_body", "body"},
    {"Cart", "cart_body", "body"},
    {"Chair", "chair_leg", "chair_base"},
    {"Clock", "clock_body", "body"},
    {"CoffeeMachine", "coffee_machine_body", "body"},
    {"Dishwasher", "dishwasher_body", "body"},
    {"Dispenser", "dispenser_body", "body"},
    {"Door", "door_frame", "frame"},
    {"Eyeglasses", "glasses_body", "frame"},
    {"Fan", "fan_frame", "frame"},
    {"Faucet", "faucet_base", "base"},
    {"FoldingChair", "chair_leg", "leg"},
    {"Refrigerator", "refrigerator_body", "body"},
    {"Globe", "globe_frame", "frame"},
    {"Kettle", "kettle_body", "body"},
    {"Keyboard", "keyboard_base", "base"},
    {"Knife", "knife_body", "handle"},
    {"Lamp", "lamp_base", "base"},
    {"Laptop", "laptop_base", "base"},
    {"Lighter", "lighter_body", "body"},
    {"Microwave", "microwave_body", "body"},
    {"Display", "display_base", "base"},
    {"Mouse", "mouse_body", "body"},
    {"Oven", "oven_body", "body"},
    {"Pen", "pen_body", "body"},
    {"Phone", "phone_base", "base"},
    {"Pliers", "leg", "leg"},
    {"KitchenPot", "pot_body", "body"},
    {"Printer", "printer_body", "body"},
    {"Remote", "remote_base", "base"},
    {"Safe", "safe_body", "body"},
    {"Scissors", "leg", "leg"},
    {"Stapler", "stapler_base", "base"},
    {"Suitcase", "suitcase_body", "body"},
    {"Switch", "switch_frame", "frame"},
    {"Table", "furniture_body", "table_frame"},
    {"Toaster", "toaster_body", "body"},
    {"Toilet", "toilet_body", "body"},
    {"TrashCan", "trashcan_body", "body"},
    {"USB", "usb_body", "body"},
    {"WashingMachine", "washing_machine_body", "body"},
    {"Window", "window_frame", "frame"},
};

/// A moving link: builder key -> semantics label, PartNet name. Category "*" holds the defaults.
/// A '%' in the label stands for the motion: "rotation" (hinges and sliders that also turn) or
/// "translation" (sliders).
struct PartLabel {
  const char* category;
  const char* key;
  const char* label;
  const char* partnet;
};

const PartLabel kParts[] = {
    // category-specific names first
    {"StorageFurniture", "door", "%_door", "cabinet_door"},
    {"Table", "door", "%_door", "cabinet_door"},
    {"Bucket", "handle", "handle", "handle"},
    {"Chair", "seat", "seat", "chair_seat"},
    {"FoldingChair", "seat", "seat", "chair_seat"},
    {"Toilet", "seat", "seat", "toilet_seat"},
    {"Clock", "hand", "hand", "clock_hand"},
    {"Dispenser", "pump", "%_lid", "pump_lid"},
    {"Globe", "frame", "frame", "meridian"},
    {"Lamp", "head", "head", "lamp_head"},
    {"Lamp", "rotation_bar", "rotation_bar", "lamp_arm"},
    {"Phone", "screen", "rotation_screen", "screen"},
    {"Display", "screen", "rotation_screen", "screen"},  // (its builder says rotation_screen)
    {"Safe", "handle", "knob", "handle"},
    {"Stapler", "body", "stapler_body", "body"},
    {"Toaster", "slider", "slider", "lever"},
    {"TrashCan", "pad", "pad", "pedal"},
    {"USB", "rotation", "rotation", "cover"},
    {"USB", "lid", "%_lid", "cap"},
    {"Window", "window", "window", "sash"},
    // defaults
    {"*", "door", "%_door", "door"},
    {"*", "rotation_door", "rotation_door", "door"},
    {"*", "lid", "%_lid", "lid"},
    {"*", "rotation_lid", "rotation_lid", "lid"},
    {"*", "handle", "%_handle", "handle"},
    {"*", "rotation_handle", "rotation_handle", "handle"},
    {"*", "translation_handle", "translation_handle", "handle"},
    {"*", "translation_tray", "translation_tray", "tray"},
    {"*", "drawer", "drawer", "drawer"},
    {"*", "button", "button", "button"},
    {"*", "key", "key", "key"},
    {"*", "knob", "knob", "knob"},
    {"*", "lever", "lever", "lever"},
    {"*", "slider", "slider", "slider"},
    {"*", "switch", "switch", "switch"},
    {"*", "wheel", "wheel", "wheel"},
    {"*", "caster", "caster", "caster"},
    {"*", "seat", "seat", "seat"},
    {"*", "leg", "leg", "leg"},
    {"*", "screen", "screen", "screen"},
    {"*", "rotation_screen", "rotation_screen", "screen"},
    {"*", "spout", "spout", "spout"},
    {"*", "rotor", "rotor", "rotor"},
    {"*", "lens", "lens", "lens"},
    {"*", "cap", "cap", "cap"},
    {"*", "container", "container", "container"},
    {"*", "blade", "blade", "blade"},
    {"*", "sphere", "sphere", "sphere"},
};

const PartLabel* FindPart(const std::string& category, const std::string& key) {
  for (const char* c : {category.c_str(), "*"}) {
    for (const PartLabel& p : kParts) {
      if (key == p.key && std::strcmp(c, p.category) == 0) return &p;
    }
  }
  return nullptr;
}

/// '%' of a label turned into the motion of a link.
std::string WithMotion(std::string label, const std::string& joint, bool rotates) {
  if (size_t k = label.find('%'); k != std::string::npos) {
    const bool translation = joint == "slider" && !rotates;
    label.replace(k, 1, translation ? "translation" : "rotation");
  }
  return label;
}

}  // namespace

std::string SemanticLabelOf(const std::string& category, const std::string& partnet_name, bool root,
                            const std::string& joint, bool rotates) {
  if (root) {
    for (const BodyLabel& b : kBodies)
      if (category == b.category) return b.label;
    return "";
  }
  for (const char* c : {category.c_str(), "*"})
    for (const PartLabel& p : kParts)
      if (partnet_name == p.partnet && std::strcmp(c, p.category) == 0)
        return WithMotion(p.label, joint, rotates);
  return "";
}

void ApplyLabels(GeneratedObject* object) {
  for (GeneratedLink& l : object->links) {
    if (l.parent < 0) {
      const BodyLabel* body = nullptr;
      for (const BodyLabel& b : kBodies) {
        if (object->category == b.category) body = &b;
      }
      if (!body) throw Error("generator: no body label for category '" + object->category + "'");
      l.name = body->label;
      l.partnet_name = body->partnet;
      continue;
    }
    const PartLabel* p = FindPart(object->category, l.name);
    if (!p) {
      throw Error("generator: no label for " + object->category + " link key '" + l.name + "'");
    }
    l.name = WithMotion(p->label, l.joint, l.rotates);
    l.partnet_name = p->partnet;
  }
}

}  // namespace partsim::internal::gen
