// An independent referring-expression matcher and word helpers for the language tests. The matcher
// lists every truthful phrasing of an object ("the [size] [colour] [material] <noun or its head
// words> [with the <colour> <part>]") as strings, so an expression refers to an object exactly when
// it is one of that set; it shares no code with language/referring.hpp's could_refer_to. The word
// helpers compare wording whole word by whole word, case-insensitively ("frame" is a word of
// "Picture Frame", "can" is not a word of "candle"); a placeholder such as "{B}" is one word of a
// text and stands for one or more words in a phrase looked for. The
// wording checks list what training instructions are made of (seen nouns, relation phrases and
// templates) and what only evaluation may say (unseen nouns and relation phrases).
#pragma once

#include <cctype>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "manisoft/assets/asset.hpp"
#include "manisoft/language/library.hpp"
#include "manisoft/language/referring.hpp"

namespace manisoft::test {

/// The lower-case words of `text`: runs of letters, digits and apostrophes, and "{X}" placeholders.
inline std::vector<std::string> words_of(const std::string& text) {
  std::vector<std::string> out;
  std::string word;
  const auto flush = [&] {
    if (!word.empty()) out.push_back(word);
    word.clear();
  };
  for (std::size_t i = 0; i < text.size(); ++i) {
    const unsigned char c = static_cast<unsigned char>(text[i]);
    if (c == '{') {
      flush();
      const std::size_t end = text.find('}', i);
      out.push_back(text.substr(i, end == std::string::npos ? std::string::npos : end - i + 1));
      if (end == std::string::npos) break;
      i = end;
    } else if (std::isalnum(c) || c == '\'') {
      word += static_cast<char>(std::tolower(c));
    } else {
      flush();
    }
  }
  flush();
  return out;
}

/// Do the words of `text` from its t-th on begin with a reading of `phrase` from its p-th on, a
/// placeholder standing for one or more words ("halfway between the cup and the mug" reads as
/// "halfway between {B} and {C}")?
inline bool reads_as(const std::vector<std::string>& text, std::size_t t, const std::vector<std::string>& phrase, std::size_t p) {
  if (p == phrase.size()) return true;
  if (t == text.size()) return false;
  if (phrase[p].front() == '{') {
    for (std::size_t next = t + 1; next <= text.size(); ++next)
      if (reads_as(text, next, phrase, p + 1)) return true;
    return false;
  }
  return text[t] == phrase[p] && reads_as(text, t + 1, phrase, p + 1);
}

/// Is some run of consecutive words of `text` a reading of `phrase` (placeholders: any words)?
inline bool says(const std::string& text, const std::string& phrase) {
  const std::vector<std::string> t = words_of(text), p = words_of(phrase);
  for (std::size_t at = 0; at < t.size(); ++at)
    if (!p.empty() && reads_as(t, at, p, 0)) return true;
  return false;
}

/// What training instructions are made of: every seen noun, relation phrase and task template.
inline std::vector<std::string> seen_wording(const language::Library& library) {
  std::vector<std::string> out;
  for (const auto* group : {&library.nouns, &library.relations, &library.templates})
    for (const auto& [name, split] : *group) out.insert(out.end(), split.seen.begin(), split.seen.end());
  return out;
}

/// Every unseen noun and unseen relation phrase, as (category or relation kind, wording).
inline std::vector<std::pair<std::string, std::string>> unseen_wording(const language::Library& library) {
  std::vector<std::pair<std::string, std::string>> out;
  for (const auto* group : {&library.nouns, &library.relations})
    for (const auto& [name, split] : *group)
      for (const std::string& u : split.unseen) out.emplace_back(name, u);
  return out;
}

/// Each unseen noun or relation phrase that is a run of words of some seen wording, as
/// "<name>: unseen '<u>' is in seen '<s>'".
inline std::vector<std::string> wording_leaks(const language::Library& library) {
  std::vector<std::string> out;
  const std::vector<std::string> seen = seen_wording(library);
  for (const auto& [name, u] : unseen_wording(library))
    for (const std::string& s : seen)
      if (says(s, u)) out.push_back(name + ": unseen '" + u + "' is in seen '" + s + "'");
  return out;
}

/// The words of unseen nouns and relation phrases that no seen wording has ("canteen", "beyond").
inline std::set<std::string> unseen_only_words(const language::Library& library) {
  std::set<std::string> seen_words, out;
  for (const std::string& s : seen_wording(library))
    for (const std::string& w : words_of(s)) seen_words.insert(w);
  for (const auto& [name, u] : unseen_wording(library))
    for (const std::string& w : words_of(u))
      if (!seen_words.count(w) && w.front() != '{') out.insert(w);
  return out;
}

/// Every truthful phrasing of an object of `asset` whose main part has colour `scene_color`
/// (empty: the asset's own), with the nouns of `library` (seen and unseen, and their head words).
inline std::set<std::string> truthful_phrasings(const language::Library& library, const assets::Asset& a,
                                                const std::string& scene_color = "") {
  const std::string color = scene_color.empty() ? a.attributes.color_name : scene_color;
  std::set<std::string> nouns;
  const language::Split split = library.nouns_of(a.category);
  for (const auto* list : {&split.seen, &split.unseen})
    for (const std::string& n : *list)
      for (std::size_t at = 0; at != std::string::npos; at = n.find(' ', at + 1)) nouns.insert(at == 0 ? n : n.substr(at + 1));
  std::vector<std::string> clauses{""};
  for (std::size_t k = 0; k < a.visual.size(); ++k)
    clauses.push_back(" with the " + (k == 0 ? color : a.visual[k].color_name) + " " + a.visual[k].name);
  std::set<std::string> out;
  const std::string size = assets::to_string(a.attributes.size);
  for (const auto& noun : nouns)
    for (int mask = 0; mask < 8; ++mask)
      for (const auto& clause : clauses) {
        std::string s = "the ";
        if (mask & 1) s += size + " ";
        if (mask & 2) s += color + " ";
        if (mask & 4) s += a.attributes.material_name + " ";
        out.insert(s + noun + clause);
      }
  return out;
}

/// How many objects of `scene` `expression` truthfully describes.
inline int count_matches(const language::Library& library, const std::string& expression,
                         const std::vector<language::SceneObject>& scene) {
  int n = 0;
  for (const auto& o : scene) n += truthful_phrasings(library, *o.asset, o.color_name).count(expression) ? 1 : 0;
  return n;
}

}  // namespace manisoft::test
