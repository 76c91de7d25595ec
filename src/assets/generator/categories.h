// Category builders of the object generator, one per PartNet-Mobility category. Each builds one
// object at rest into the builder, drawing its shape from the random generator.
#pragma once

#include "assets/generator/object_builder.h"

namespace partsim::internal::gen {

using CategoryBuilder = void (*)(ObjectBuilder& b, Rng& rng);

// furniture.cc
void BuildStorageFurniture(ObjectBuilder& b, Rng& rng);
void BuildTable(ObjectBuilder& b, Rng& rng);
void BuildChair(ObjectBuilder& b, Rng& rng);
void BuildFoldingChair(ObjectBuilder& b, Rng& rng);
void BuildDoor(ObjectBuilder& b, Rng& rng);
void BuildWindow(ObjectBuilder& b, Rng& rng);
void BuildToilet(ObjectBuilder& b, Rng& rng);
void BuildTrashCan(ObjectBuilder& b, Rng& rng);
void BuildCart(ObjectBuilder& b, Rng& rng);
void BuildSafe(ObjectBuilder& b, Rng& rng);
void BuildBox(ObjectBuilder& b, Rng& rng);
void BuildSuitcase(ObjectBuilder& b, Rng& rng);

// appliances.cc
void BuildDishwasher(ObjectBuilder& b, Rng& rng);
void BuildMicrowave(ObjectBuilder& b, Rng& rng);
void BuildOven(ObjectBuilder& b, Rng& rng);
void BuildRefrigerator(ObjectBuilder& b, Rng& rng);
void BuildWashingMachine(ObjectBuilder& b, Rng& rng);
void BuildCoffeeMachine(ObjectBuilder& b, Rng& rng);
void BuildToaster(ObjectBuilder& b, Rng& rng);
void BuildPrinter(ObjectBuilder& b, Rng& rng);
void BuildFan(ObjectBuilder& b, Rng& rng);
void BuildLamp(ObjectBuilder& b, Rng& rng);
void BuildDisplay(ObjectBuilder& b, Rng& rng);
void BuildKettle(ObjectBuilder& b, Rng& rng);
void BuildKitchenPot(ObjectBuilder& b, Rng& rng);
void BuildDispenser(ObjectBuilder& b, Rng& rng);
void BuildFaucet(ObjectBuilder& b, Rng& rng);

// small_objects.cc
void BuildBottle(ObjectBuilder& b, Rng& rng);
void BuildBucket(ObjectBuilder& b, Rng& rng);
void BuildCamera(ObjectBuilder& b, Rng& rng);
void BuildClock(ObjectBuilder& b, Rng& rng);
void BuildEyeglasses(ObjectBuilder& b, Rng& rng);
void BuildGlobe(ObjectBuilder& b, Rng& rng);
void BuildKeyboard(ObjectBuilder& b, Rng& rng);
void BuildLaptop(ObjectBuilder& b, Rng& rng);
void BuildLighter(ObjectBuilder& b, Rng& rng);
void BuildMouse(ObjectBuilder& b, Rng& rng);
void BuildPen(ObjectBuilder& b, Rng& rng);
void BuildPhone(ObjectBuilder& b, Rng& rng);
void BuildRemote(ObjectBuilder& b, Rng& rng);
void BuildSwitch(ObjectBuilder& b, Rng& rng);
void BuildUSB(ObjectBuilder& b, Rng& rng);

// tools.cc
void BuildKnife(ObjectBuilder& b, Rng& rng);
void BuildPliers(ObjectBuilder& b, Rng& rng);
void BuildScissors(ObjectBuilder& b, Rng& rng);
void BuildStapler(ObjectBuilder& b, Rng& rng);

// labels.cc
/// Turns each link's builder key (GeneratedLink::name as the builders set it: "door", "lid",
/// "knob", ...) into its semantics.txt label and its mobility_v2.json PartNet name, from the
/// category's tables; the body (the link joined to base) gets the category's body label. Throws
/// partsim::Error naming a (category, key) that has no entry.
void ApplyLabels(GeneratedObject* object);
/// The semantics.txt label the tables give a link with PartNet name `partnet_name` in
/// `category`: the category's body label for a root, else the label of the first entry (the
/// category's own, then the defaults) with that PartNet name, its '%' turned into the motion
/// ("rotation" for hinges and sliders that also turn, "translation" for sliders). "" when the
/// tables have none (the annotation tool's export then uses the PartNet name).
std::string SemanticLabelOf(const std::string& category, const std::string& partnet_name, bool root,
                            const std::string& joint, bool rotates);

}  // namespace partsim::internal::gen
