// Referring expressions: how an instruction names an object on the table ("the yellow bottle",
// "the bottle with the green cap", "the small ceramic bowl"), built from the assets' attributes
// (assets::Attributes and the visual parts' colours; the ManiSoft benchmark paper, section 3.5,
// asks for attribute-aware descriptions in randomized scenes).
//
// A scene may recolour an object (SceneObject::color_name): the expressions use the scene's colour.
// Every expression produced identifies its object uniquely among ALL objects and obstacles on
// the table: an expression is kept only if no other object could be meant by it under any reading
// of its words (could_refer_to). A noun names an object when one of the object's category nouns (seen or
// unseen) is that noun or ends with it as a word: "bottle" names a "pill bottle" too, "can" a
// "watering can", so "the bottle" is never said beside a pill bottle. Colour and material are the
// main part's; size is the asset's size class; a part clause ("with the green cap") needs a part of
// that name and colour. Objects whose every expression is ambiguous get none (the caller redraws).
#pragma once

#include <Eigen/Core>

#include <algorithm>
#include <span>
#include <utility>
#include <string>
#include <vector>

#include "manisoft/assets/asset.hpp"
#include "manisoft/language/library.hpp"

namespace manisoft::language {

/// An object or obstacle on the table, as language sees it.
struct SceneObject {
  const assets::Asset* asset = nullptr;
  Eigen::Vector3d position{Eigen::Vector3d::Zero()};  ///< world, m
  std::string color_name;  ///< the scene's colour of the main part; empty: the asset's own

  const std::string& main_color() const { return color_name.empty() ? asset->attributes.color_name : color_name; }
};

/// What an expression says about its object.
struct Description {
  std::string noun;
  std::string color;     ///< main colour, "" = not said
  std::string size;      ///< size class, "" = not said
  std::string material;  ///< main material, "" = not said
  std::string part;      ///< part clause: part name, "" = none
  std::string part_color;

  std::string text() const {
    std::string s = "the ";
    for (const std::string* word : {&size, &color, &material})
      if (!word->empty()) s += *word + " ";
    s += noun;
    if (!part.empty()) s += " with the " + part_color + " " + part;
    return s;
  }
};

/// Does `noun` name an object of `category` (a category noun equal to it or ending with it)?
inline bool noun_names(const Library& library, const std::string& noun, const std::string& category) {
  const Split nouns = library.nouns_of(category);
  for (const auto* list : {&nouns.seen, &nouns.unseen})
    for (const std::string& n : *list)
      if (n == noun || (n.size() > noun.size() && n.ends_with(noun) && n[n.size() - noun.size() - 1] == ' ')) return true;
  return false;
}

/// The parts that can tell an object apart: named visual parts after the first (the body) whose
/// colour differs from the main colour, as (part name, colour).
inline std::vector<std::pair<std::string, std::string>> distinctive_parts(const SceneObject& object) {
  const assets::Asset& asset = *object.asset;
  std::vector<std::pair<std::string, std::string>> parts;
  for (std::size_t k = 1; k < asset.visual.size(); ++k) {
    const auto& p = asset.visual[k];
    if (!p.name.empty() && !p.color_name.empty() && p.color_name != object.main_color())
      parts.emplace_back(p.name, p.color_name);
  }
  return parts;
}

/// Can `text` ("the small yellow plastic bottle with the green cap") refer to `asset`? Every way
/// of reading it counts: the words before the noun are any of the asset's size, colour and
/// material (in that order, each optional) and the rest a noun of its category (or its head
/// words), so "the glass jar" also refers to a glass candle jar ("candle jar" ends with "jar").
inline bool could_refer_to(const Library& library, const std::string& text, const SceneObject& object) {
  const assets::Asset& asset = *object.asset;
  if (!text.starts_with("the ")) return false;
  std::string rest = text.substr(4);
  const std::size_t with = rest.find(" with the ");
  if (with != std::string::npos) {
    const std::string clause = rest.substr(with + 10);
    rest = rest.substr(0, with);
    bool found = false;
    for (std::size_t k = 0; k < asset.visual.size(); ++k) {
      const auto& p = asset.visual[k];
      found = found || clause == (k == 0 ? object.main_color() : p.color_name) + " " + p.name;
    }
    if (!found) return false;
  }
  const auto& a = asset.attributes;
  const std::string size = assets::to_string(a.size);
  for (std::size_t cut = 0; cut != std::string::npos; cut = rest.find(' ', cut + 1)) {
    const std::string words = cut == 0 ? "" : rest.substr(0, cut);
    const std::string noun = cut == 0 ? rest : rest.substr(cut + 1);
    if (!noun_names(library, noun, asset.category)) continue;
    for (int mask = 0; mask < 8; ++mask) {
      std::string said;
      const auto append = [&said](const std::string& w) { said += said.empty() ? w : " " + w; };
      if (mask & 1) append(size);
      if (mask & 2) append(object.main_color());
      if (mask & 4) append(a.material_name);
      if (said == words) return true;
    }
  }
  return false;
}

/// Unique descriptions of objects[target] with the seen (or unseen) nouns of its category, in
/// order of preference (shortest first: noun; colour; size; material; part; then combinations).
inline std::vector<Description> referring_expressions(const Library& library, std::span<const SceneObject> objects, int target,
                                                      bool seen_nouns = true) {
  if (target < 0 || target >= static_cast<int>(objects.size()))
    ::manisoft::detail::fail("referring_expressions: target ", target, " is outside the ", objects.size(), " objects");
  for (std::size_t i = 0; i < objects.size(); ++i)
    if (objects[i].asset == nullptr) ::manisoft::detail::fail("referring_expressions: object ", i, " has no asset");
  const SceneObject& object = objects[static_cast<std::size_t>(target)];
  const assets::Asset& asset = *object.asset;
  const auto& a = asset.attributes;
  const std::string size = assets::to_string(a.size);
  const auto parts = distinctive_parts(object);
  const Split nouns = library.nouns_of(asset.category);
  const auto& noun_list = nouns.of(seen_nouns).empty() ? nouns.seen : nouns.of(seen_nouns);

  std::vector<Description> forms;
  const auto add = [&forms](const std::string& noun, const std::string& color, const std::string& size_word,
                            const std::string& material, const std::string& part = "", const std::string& part_color = "") {
    forms.push_back(Description{noun, color, size_word, material, part, part_color});
  };
  const std::string& color = object.main_color();
  const std::string& material = a.material_name;
  for (const std::string& noun : noun_list) {
    add(noun, "", "", "");
    if (!color.empty()) add(noun, color, "", "");
    add(noun, "", size, "");
    if (!material.empty()) add(noun, "", "", material);
    for (const auto& [part, part_color] : parts) add(noun, "", "", "", part, part_color);
    if (!color.empty()) add(noun, color, size, "");
    if (!color.empty() && !material.empty()) add(noun, color, "", material);
    if (!color.empty() && !material.empty()) add(noun, color, size, material);
    if (!color.empty())
      for (const auto& [part, part_color] : parts) add(noun, color, "", "", part, part_color);
  }
  std::stable_sort(forms.begin(), forms.end(), [](const Description& x, const Description& y) {
    const auto said = [](const Description& d) {
      return int(!d.color.empty()) + int(!d.size.empty()) + int(!d.material.empty()) + int(!d.part.empty());
    };
    return said(x) < said(y);
  });
  std::vector<Description> unique;
  for (const Description& d : forms) {
    bool ambiguous = false;
    for (std::size_t j = 0; j < objects.size() && !ambiguous; ++j)
      ambiguous = static_cast<int>(j) != target && could_refer_to(library, d.text(), objects[j]);
    if (!ambiguous) unique.push_back(d);
  }
  return unique;
}

}  // namespace manisoft::language
