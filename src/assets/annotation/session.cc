// The question generator of the annotation procedure (docs/annotation.md): the state that the
// answers so far make, the next question, and the checks that keep the links a forest with each
// part in exactly one link. The state is a function of the list of answers: Undo replays all
// but the last.
#include <algorithm>
#include <cmath>
#include <set>
#include <utility>

#include "core/json_parse.h"
#include "partsim/assets/annotation.h"
#include "partsim/core/error.h"

namespace partsim {
namespace {

using Json = nlohmann::json;

std::string Quote(const std::string& s) { return "\"" + s + "\""; }

bool Finite(const Eigen::Vector3d& v) { return v.allFinite(); }

}  // namespace

const char* AnnotationPhaseName(AnnotationPhase phase) {
  switch (phase) {
    case AnnotationPhase::kMotion:
      return "motion";
    case AnnotationPhase::kFixed:
      return "fixed";
    case AnnotationPhase::kHinge:
      return "hinge";
    case AnnotationPhase::kSlider:
      return "slider";
    case AnnotationPhase::kRoot:
      return "root";
    case AnnotationPhase::kDone:
      return "done";
  }
  return "?";
}

AnnotationSession::AnnotationSession(std::shared_ptr<const AnnotationInput> input)
    : input_(std::move(input)) {
  if (!input_) throw Error("AnnotationSession: no input");
  leaf_link_.assign(input_->nodes.size(), -1);
  for (auto it = input_->roots.rbegin(); it != input_->roots.rend(); ++it) queue_.push_back(*it);
  Advance();
}

std::vector<int> AnnotationSession::Units() const {
  std::vector<int> u = units_;
  std::sort(u.begin(), u.end());
  return u;
}

int AnnotationSession::LinkIndex(int id) const {
  for (size_t i = 0; i < links_.size(); ++i)
    if (links_[i].id == id) return static_cast<int>(i);
  return -1;
}

const AnnotationLink& AnnotationSession::Link(int id) const {
  const int i = LinkIndex(id);
  if (i < 0) throw Error("no link " + std::to_string(id));
  return links_[i];
}

void AnnotationSession::AddUnit(int top) {
  units_.push_back(top);
  AnnotationLink l;
  l.id = input_->nodes[top].id;
  l.units = {top};
  l.leaves = input_->Leaves(top);
  for (int leaf : l.leaves) leaf_link_[leaf] = static_cast<int>(links_.size());
  links_.push_back(std::move(l));
}

int AnnotationSession::Components() const {
  int n = 0;
  for (const AnnotationLink& l : links_) n += l.parent < 0;
  return n;
}

bool AnnotationSession::AnyMergePossible() const {
  // a merge of links A and B is refused only when a node answered "moves" has all its parts in
  // A and B: such nodes whose parts span exactly two links forbid that pair
  const size_t n = links_.size();
  if (n < 2) return false;
  std::set<std::pair<int, int>> forbidden;
  for (int m : moving_) {
    std::set<int> spans;
    for (int leaf : input_->Leaves(m)) {
      spans.insert(leaf_link_[leaf]);
      if (spans.size() > 2) break;
    }
    if (spans.size() == 2) forbidden.insert({*spans.begin(), *spans.rbegin()});
  }
  return forbidden.size() < n * (n - 1) / 2;
}

void AnnotationSession::Advance() {
  const AnnotationInput& in = *input_;
  question_ = AnnotationQuestion();
  question_.index = static_cast<int>(answers_.size());
  // 1. the traversal: a node with one child asks what its child would; a leaf is a unit
  while (!queue_.empty()) {
    const int top = queue_.back();
    int n = top;
    while (in.nodes[n].children.size() == 1) n = in.nodes[n].children[0];
    if (in.nodes[n].children.empty()) {
      queue_.pop_back();
      AddUnit(top);
      continue;
    }
    asked_top_ = top;
    question_.phase = AnnotationPhase::kMotion;
    question_.node = in.nodes[n].id;
    question_.text = "Do the parts of " + Quote(in.nodes[n].text) + " move relative to each other?";
    return;
  }
  // the links in pre-order of their units: the same order whatever the answers' order was
  if (!links_sorted_) {
    std::sort(links_.begin(), links_.end(),
              [](const AnnotationLink& a, const AnnotationLink& b) { return a.units < b.units; });
    for (size_t i = 0; i < links_.size(); ++i)
      for (int leaf : links_[i].leaves) leaf_link_[leaf] = static_cast<int>(i);
    links_sorted_ = true;
    phase_ = AnnotationPhase::kFixed;
  }
  // 2. fixed groups, while a merge is possible and none answered "none"
  if (phase_ == AnnotationPhase::kFixed) {
    if (AnyMergePossible()) {
      question_.phase = AnnotationPhase::kFixed;
      question_.text = "Which parts are fixed together? Select two or more, or none.";
      return;
    }
    phase_ = AnnotationPhase::kHinge;
  }
  // 3. and 4. joints, while the links are not one tree
  for (AnnotationPhase p : {AnnotationPhase::kHinge, AnnotationPhase::kSlider}) {
    if (phase_ != p) continue;
    if (Components() > 1) {
      question_.phase = p;
      question_.text = p == AnnotationPhase::kHinge
                           ? "Which two parts are joined by a hinge? Choose parent and child, "
                             "the axis and the limits, or none."
                           : "Which two parts are joined by a slider? Choose parent and child, "
                             "the axis and the limits, whether it also turns, or none.";
      return;
    }
    phase_ = p == AnnotationPhase::kHinge ? AnnotationPhase::kSlider : AnnotationPhase::kRoot;
  }
  // 5. each root: fixed, free or outlier
  phase_ = AnnotationPhase::kRoot;
  for (const AnnotationLink& l : links_) {
    if (l.parent >= 0 || !l.root.empty()) continue;
    question_.phase = AnnotationPhase::kRoot;
    question_.link = l.id;
    question_.text =
        "Is " + Quote(in.nodes[l.units[0]].text) + " (a root) fixed, free, or an outlier?";
    return;
  }
  phase_ = AnnotationPhase::kDone;
  question_.phase = AnnotationPhase::kDone;
  question_.text = "Every question is answered: export the object.";
}

void AnnotationSession::Apply(const AnnotationAnswer& a) {
  const AnnotationInput& in = *input_;
  if (a.index != question_.index)
    throw Error("the answer is to question " + std::to_string(a.index) + ", the question now is " +
                std::to_string(question_.index) + " (answered already, or not yet asked)");
  switch (question_.phase) {
    case AnnotationPhase::kMotion: {
      const int top = asked_top_;
      queue_.pop_back();
      if (a.moves) {
        moving_.push_back(in.Index(question_.node));
        const auto& ch = in.nodes[in.Index(question_.node)].children;
        for (auto it = ch.rbegin(); it != ch.rend(); ++it) queue_.push_back(*it);
      } else {
        AddUnit(top);
      }
      return;
    }
    case AnnotationPhase::kFixed: {
      if (a.none) {
        phase_ = AnnotationPhase::kHinge;
        return;
      }
      std::set<int> chosen;
      for (int id : a.links) {
        if (LinkIndex(id) < 0) throw Error("there is no link " + std::to_string(id));
        chosen.insert(LinkIndex(id));
      }
      if (chosen.size() < 2) throw Error("choose two or more different parts to fix together");
      for (int m : moving_) {
        bool all = true;
        for (int leaf : in.Leaves(m)) all = all && chosen.count(leaf_link_[leaf]);
        if (all)
          throw Error("fixing these together would fix every part of " + Quote(in.nodes[m].text) +
                      ", which was answered to move");
      }
      // merge into the first (lowest pre-order) link
      const int into = *chosen.begin();
      for (auto it = chosen.rbegin(); it != chosen.rend(); ++it) {
        if (*it == into) continue;
        AnnotationLink& dst = links_[into];
        const AnnotationLink& src = links_[*it];
        dst.units.insert(dst.units.end(), src.units.begin(), src.units.end());
        dst.leaves.insert(dst.leaves.end(), src.leaves.begin(), src.leaves.end());
        links_.erase(links_.begin() + *it);
      }
      std::sort(links_[into].units.begin(), links_[into].units.end());
      std::sort(links_[into].leaves.begin(), links_[into].leaves.end());
      links_[into].id = in.nodes[links_[into].units[0]].id;
      for (size_t i = 0; i < links_.size(); ++i)
        for (int leaf : links_[i].leaves) leaf_link_[leaf] = static_cast<int>(i);
      return;
    }
    case AnnotationPhase::kHinge:
    case AnnotationPhase::kSlider: {
      const bool hinge = question_.phase == AnnotationPhase::kHinge;
      if (a.none) {
        phase_ = hinge ? AnnotationPhase::kSlider : AnnotationPhase::kRoot;
        return;
      }
      const int p = LinkIndex(a.parent), c = LinkIndex(a.child);
      if (p < 0) throw Error("there is no parent link " + std::to_string(a.parent));
      if (c < 0) throw Error("there is no child link " + std::to_string(a.child));
      if (p == c) throw Error("a part cannot be joined to itself");
      if (links_[c].parent >= 0)
        throw Error("link " + std::to_string(a.child) + " already hangs on link " +
                    std::to_string(links_[c].parent) + ": a part has one parent");
      for (int up = p; up >= 0; up = LinkIndex(links_[up].parent))
        if (up == c)
          throw Error("link " + std::to_string(a.parent) + " hangs below link " +
                      std::to_string(a.child) + ": the joint would close a loop");
      if (!Finite(a.origin)) throw Error("the axis origin is not a finite point");
      if (!Finite(a.direction) || a.direction.norm() < 1e-9)
        throw Error("the axis direction is not a finite, non-zero vector");
      const bool limited = hinge ? !a.no_limit : true;
      if (limited && (!std::isfinite(a.lower) || !std::isfinite(a.upper) || a.lower > a.upper))
        throw Error("the limits must be finite numbers with lower <= upper (got " +
                    std::to_string(a.lower) + ", " + std::to_string(a.upper) + ")");
      if (!hinge && a.rotates && !a.no_rotation_limit &&
          !(std::isfinite(a.rotation_limit) && a.rotation_limit >= 0))
        throw Error("the rotation limit must be a number of degrees >= 0");
      AnnotationLink& l = links_[c];
      l.parent = a.parent;
      l.joint = hinge ? "hinge" : "slider";
      l.origin = a.origin;
      l.direction = a.direction.normalized();
      // a hinge without limit keeps the numbers it was given (the dataset writes -180, 180)
      l.lower = std::isfinite(a.lower) ? a.lower : 0;
      l.upper = std::isfinite(a.upper) ? a.upper : 0;
      l.no_limit = hinge && a.no_limit;
      l.rotates = !hinge && a.rotates;
      l.no_rotation_limit = l.rotates && a.no_rotation_limit;
      l.rotation_limit = l.rotates && !a.no_rotation_limit ? a.rotation_limit : 0;
      return;
    }
    case AnnotationPhase::kRoot: {
      if (a.kind != "fixed" && a.kind != "free" && a.kind != "outlier")
        throw Error("a root is \"fixed\", \"free\" or \"outlier\", not " + Quote(a.kind));
      links_[LinkIndex(question_.link)].root = a.kind;
      return;
    }
    case AnnotationPhase::kDone:
      throw Error("every question is answered already");
  }
}

void AnnotationSession::Answer(AnnotationAnswer answer) {
  // checked and applied on a copy: a refused answer leaves this session as it was
  AnnotationSession next = *this;
  next.Apply(answer);
  next.asked_.push_back(question_);
  next.answers_.push_back(std::move(answer));
  next.Advance();
  *this = std::move(next);
}

bool AnnotationSession::Undo() {
  if (answers_.empty()) return false;
  std::vector<AnnotationAnswer> keep(answers_.begin(), answers_.end() - 1);
  AnnotationSession fresh(input_);
  for (AnnotationAnswer& a : keep) fresh.Answer(std::move(a));
  fresh.reviews_.clear();
  *this = std::move(fresh);
  return true;
}

void AnnotationSession::Review(const AnnotationReview& review) {
  if (!Done()) throw Error("a review waits until every question is answered");
  const int i = LinkIndex(review.link);
  if (i < 0 || links_[i].joint.empty())
    throw Error("link " + std::to_string(review.link) + " has no joint to review");
  for (AnnotationReview& r : reviews_)
    if (r.link == review.link) {
      r = review;
      return;
    }
  reviews_.push_back(review);
}

namespace {

Json Vec(const Eigen::Vector3d& v) { return Json::array({v.x(), v.y(), v.z()}); }

Json LinkJson(const AnnotationInput& in, const AnnotationLink& l) {
  Json units = Json::array(), leaves = Json::array();
  for (int u : l.units) units.push_back(in.nodes[u].id);
  for (int f : l.leaves) leaves.push_back(in.nodes[f].id);
  Json j = {{"id", l.id},
            {"units", units},
            {"leaves", leaves},
            {"name", in.nodes[l.units[0]].name},
            {"parent", l.parent},
            {"joint", l.joint.empty() ? Json(nullptr) : Json(l.joint)},
            {"root", l.root.empty() ? Json(nullptr) : Json(l.root)}};
  if (!l.joint.empty()) {
    j["axis"] = {{"origin", Vec(l.origin)}, {"direction", Vec(l.direction)}};
    j["limit"] = {{"a", l.lower},
                  {"b", l.upper},
                  {"noLimit", l.no_limit},
                  {"rotates", l.rotates},
                  {"noRotationLimit", l.no_rotation_limit},
                  {"rotationLimit", l.rotation_limit}};
  }
  return j;
}

}  // namespace

std::string AnnotationSession::StateJson(bool review_mode) const {
  const AnnotationInput& in = *input_;
  const bool reviewing = review_mode && Done();
  Json q = {{"index", question_.index},
            {"phase", reviewing ? "review" : AnnotationPhaseName(question_.phase)},
            {"text", reviewing ? "Review each joint: watch it move, then accept or reject it."
                               : question_.text},
            {"node", question_.node >= 0 ? Json(question_.node) : Json(nullptr)},
            {"link", question_.link >= 0 ? Json(question_.link) : Json(nullptr)}};
  Json units = Json::array(), links = Json::array(), history = Json::array();
  for (int u : Units()) {
    Json leaves = Json::array();
    for (int f : in.Leaves(u)) leaves.push_back(in.nodes[f].id);
    units.push_back({{"node", in.nodes[u].id}, {"leaves", leaves}});
  }
  for (const AnnotationLink& l : links_) links.push_back(LinkJson(in, l));
  for (size_t i = 0; i < answers_.size(); ++i)
    history.push_back({{"phase", AnnotationPhaseName(asked_[i].phase)},
                       {"text", asked_[i].text},
                       {"answer", Json::parse(AnnotationAnswerToJson(answers_[i]))}});
  Json j = {
      {"question", q},      {"units", units}, {"links", links},   {"answers", answers_.size()},
      {"history", history}, {"done", Done()}, {"review", nullptr}};
  if (review_mode) {
    Json joints = Json::array();
    bool all = Done();
    for (const AnnotationLink& l : links_) {
      if (l.joint.empty()) continue;
      Json r = {{"link", l.id}, {"decision", nullptr}, {"comment", ""}};
      for (const AnnotationReview& rv : reviews_)
        if (rv.link == l.id)
          r = {{"link", l.id},
               {"decision", rv.accept ? "accept" : "reject"},
               {"comment", rv.comment}};
      all = all && !r["decision"].is_null();
      joints.push_back(r);
    }
    j["review"] = {{"joints", joints}, {"done", all}};
  }
  return internal::DumpJson(j);
}

AnnotationAnswer AnnotationAnswerFromJson(const std::string& text) {
  Json j;
  try {
    j = internal::ParseJsonBounded(text);
  } catch (const Json::exception& e) {
    throw Error(std::string("the answer is not JSON: ") + e.what());
  }
  if (!j.is_object()) throw Error("the answer is not a JSON object");
  AnnotationAnswer a;
  auto number = [&](const char* key, double* out) {
    if (!j.contains(key)) return;
    if (!j[key].is_number())
      throw Error(std::string("answer field \"") + key + "\" is not a number");
    *out = j[key].get<double>();
  };
  auto integer = [&](const char* key, int* out) {
    if (!j.contains(key)) return;
    if (!j[key].is_number_integer() || std::abs(j[key].get<long long>()) > (1ll << 30))
      throw Error(std::string("answer field \"") + key + "\" is not an integer");
    *out = static_cast<int>(j[key].get<long long>());
  };
  auto boolean = [&](const char* key, bool* out) {
    if (!j.contains(key)) return;
    if (!j[key].is_boolean())
      throw Error(std::string("answer field \"") + key + "\" is not true or false");
    *out = j[key].get<bool>();
  };
  auto vec = [&](const char* key, Eigen::Vector3d* out) {
    if (!j.contains(key)) return;
    const Json& v = j[key];
    if (!v.is_array() || v.size() != 3 || !v[0].is_number() || !v[1].is_number() ||
        !v[2].is_number())
      throw Error(std::string("answer field \"") + key + "\" is not a list of three numbers");
    *out = Eigen::Vector3d(v[0].get<double>(), v[1].get<double>(), v[2].get<double>());
  };
  if (!j.contains("index")) throw Error("the answer has no \"index\" (the question it answers)");
  integer("index", &a.index);
  boolean("none", &a.none);
  boolean("moves", &a.moves);
  if (j.contains("links")) {
    if (!j["links"].is_array() || j["links"].size() > static_cast<size_t>(kMaxAnnotationNodes))
      throw Error("answer field \"links\" is not a list of link ids");
    for (const Json& v : j["links"]) {
      if (!v.is_number_integer()) throw Error("answer field \"links\" holds a non-integer");
      a.links.push_back(static_cast<int>(v.get<long long>()));
    }
  }
  integer("parent", &a.parent);
  integer("child", &a.child);
  vec("origin", &a.origin);
  vec("direction", &a.direction);
  number("lower", &a.lower);
  number("upper", &a.upper);
  boolean("no_limit", &a.no_limit);
  boolean("rotates", &a.rotates);
  number("rotation_limit", &a.rotation_limit);
  boolean("no_rotation_limit", &a.no_rotation_limit);
  if (j.contains("kind")) {
    if (!j["kind"].is_string()) throw Error("answer field \"kind\" is not a string");
    a.kind = j["kind"].get<std::string>();
  }
  number("time", &a.time);
  return a;
}

std::string AnnotationAnswerToJson(const AnnotationAnswer& a) {
  Json j = {{"index", a.index}};
  if (a.none) j["none"] = true;
  j["moves"] = a.moves;
  if (!a.links.empty()) j["links"] = a.links;
  if (a.parent >= 0 || a.child >= 0) {
    j["parent"] = a.parent;
    j["child"] = a.child;
    j["origin"] = Vec(a.origin);
    j["direction"] = Vec(a.direction);
    j["lower"] = a.lower;
    j["upper"] = a.upper;
    j["no_limit"] = a.no_limit;
    j["rotates"] = a.rotates;
    j["rotation_limit"] = a.rotation_limit;
    j["no_rotation_limit"] = a.no_rotation_limit;
  }
  if (!a.kind.empty()) j["kind"] = a.kind;
  if (a.time > 0) j["time"] = a.time;
  return internal::DumpJson(j);
}

}  // namespace partsim
