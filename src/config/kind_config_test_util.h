// The config's reader and writer of one kind's keys (marker_config.cc: ReadKindParams,
// WriteKindParams), seen through the built-in kinds' own parameter types, for the tests of their
// keys (test code only): the tests exercise the same generic code a marker's entry goes through.
#pragma once

#include <string>

#include <yaml-cpp/yaml.h>

#include "config/config_sections.h"
#include "softsight/track/colour_tracker.h"
#include "softsight/track/template_tracker.h"

namespace softsight {

inline void ReadColourParams(YamlMap& marker, ColourParams* params) {
  KindSection section{*params, ""};
  ReadKindParams(marker, &section);
  *params = section.params.get<ColourParams>();
}

inline void WriteColourParams(const ColourParams& params, YAML::Emitter& out) {
  WriteKindParams({params, ""}, out);
}

// A template marker's keys: its parameters and the image file they may come from.
struct TemplateSection {
  TemplateParams params;
  std::string file;  // `template.file` as written; "" when none.
};

// The template kind's rows (KindSectionOptions) as rows of a TemplateSection.
inline const OptionTable<TemplateSection>& TemplateSectionOptions() {
  static const OptionTable<TemplateSection> table = [] {
    OptionTable<TemplateSection> rows;
    for (const Option<KindSection>& kind_row : KindSectionOptions(MarkerParams(TemplateParams{}).kind())) {
      Option<TemplateSection> row;
      static_cast<OptionSpec&>(row) = kind_row;
      row.get = [get = kind_row.get](const TemplateSection& t) {
        return get(KindSection{t.params, t.file});
      };
      row.set = [set = kind_row.set](TemplateSection& t, const std::optional<OptionValue>& v) {
        KindSection section{t.params, t.file};
        set(section, v);
        t.params = section.params.get<TemplateParams>();
        t.file = section.image_file;
      };
      if (kind_row.applies) {
        row.applies = [applies = kind_row.applies](const TemplateSection& t) {
          return applies(KindSection{t.params, t.file});
        };
      }
      rows.push_back(std::move(row));
    }
    return rows;
  }();
  return table;
}

inline void ReadTemplateParams(YamlMap& marker, TemplateSection* section) {
  KindSection kind_section{section->params, section->file};
  ReadKindParams(marker, &kind_section);
  section->params = kind_section.params.get<TemplateParams>();
  section->file = kind_section.image_file;
}

inline void WriteTemplateParams(const TemplateSection& section, YAML::Emitter& out) {
  WriteKindParams({section.params, section.file}, out);
}

}  // namespace softsight
