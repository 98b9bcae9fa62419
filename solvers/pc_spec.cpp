// SPDX-License-Identifier: MIT
// The one parser of preconditioner specs, their canonical text and the usage lines generated
// from the keys each entry declares.
#include "solvers/pc_spec.hpp"

#include "core/check.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <sstream>

namespace mlc::solvers {

std::string_view to_string(Method m) {
    switch (m) {
    case Method::schur:
        return "schur";
    case Method::lu:
        return "lu";
    case Method::krylov:
        return "krylov";
    }
    return "?";
}

std::ostream& operator<<(std::ostream& os, Method m) {
    return os << to_string(m);
}

Method parse_method(std::string_view name) {
    for (Method m : {Method::schur, Method::lu, Method::krylov})
        if (name == to_string(m)) return m;
    throw InvalidInput("unknown linear solver method '" + std::string(name) +
                       "' (known: schur, lu, krylov)");
}

MultigridParams MgOptions::cycle() const {
    MultigridParams p;
    p.pre_sweeps = pre;
    p.post_sweeps = post;
    p.omega = omega;
    p.precision = precision;
    p.smoother = smoother;
    return p;
}

namespace {

std::string_view trim(std::string_view s) {
    const auto first = s.find_first_not_of(" \t");
    if (first == std::string_view::npos) return {};
    const auto last = s.find_last_not_of(" \t");
    return s.substr(first, last - first + 1);
}

std::string lower(std::string_view s) {
    std::string out(s);
    std::transform(out.begin(), out.end(), out.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    return out;
}

// The shortest text that reads back as `v`, with the exponent's leading zeros dropped
// (1e-08 -> 1e-8).
std::string format_real(double v) {
    char buf[64];
    const auto res = std::to_chars(buf, buf + sizeof buf, v);
    std::string s(buf, res.ptr);
    const auto e = s.find('e');
    if (e == std::string::npos) return s;
    size_t d = e + 1;
    if (d < s.size() && (s[d] == '-' || s[d] == '+')) ++d;
    size_t z = d;
    while (z + 1 < s.size() && s[z] == '0')
        ++z;
    std::string out = s.substr(0, d) + s.substr(z);
    if (out[e + 1] == '+') out.erase(e + 1, 1);
    return out;
}

std::string names_of(const std::vector<std::pair<std::string_view, int>>& names,
                     std::string_view separator) {
    std::string out;
    for (const auto& [n, v] : names)
        out += (out.empty() ? "" : std::string(separator)) + std::string(n);
    return out;
}

// Binds the options of a spec's text to the fields: `given` holds key -> value text.
class Reader final : public PcFields {
public:
    Reader(const std::string& name, const std::map<std::string, std::string>& given)
        : name_(name), given_(given) {}
    void integer(std::string_view key, int& value, std::string_view) override {
        const std::string* t = find(key);
        if (t == nullptr) return;
        int v = 0;
        const auto [ptr, ec] = std::from_chars(t->data(), t->data() + t->size(), v);
        MLC_CHECK(ec == std::errc() && ptr == t->data() + t->size(),
                  "option " << key << "=" << *t << " of preconditioner '" << name_
                            << "' is not an integer");
        value = v;
    }
    void real(std::string_view key, double& value, std::string_view) override {
        const std::string* t = find(key);
        if (t == nullptr) return;
        double v = 0.0;
        const auto [ptr, ec] = std::from_chars(t->data(), t->data() + t->size(), v);
        MLC_CHECK(ec == std::errc() && ptr == t->data() + t->size() && std::isfinite(v),
                  "option " << key << "=" << *t << " of preconditioner '" << name_
                            << "' is not a number");
        value = v;
    }
    void choice(std::string_view key, int& value,
                std::initializer_list<std::pair<std::string_view, int>> names) override {
        choice_list(key, value, {names.begin(), names.end()});
    }
    void choice_list(std::string_view key, int& value,
                     const std::vector<std::pair<std::string_view, int>>& names) override {
        const std::string* t = find(key);
        if (t == nullptr) return;
        for (const auto& [n, v] : names)
            if (*t == n) {
                value = v;
                return;
            }
        MLC_CHECK(false, "option " << key << "=" << *t << " of " << name_ << ": valid "
                                   << names_of(names, ", "));
    }
    // Throws for a key no field asked for, listing the valid ones.
    void finish() const {
        for (const auto& [key, value] : given_) {
            if (std::find(used_.begin(), used_.end(), key) != used_.end()) continue;
            std::ostringstream keys;
            for (size_t i = 0; i < used_.size(); ++i)
                keys << (i ? ", " : "") << used_[i];
            MLC_CHECK(false, "unknown option '"
                                 << key << "' for preconditioner '" << name_
                                 << "'; valid options: " << (used_.empty() ? "none" : keys.str()));
        }
    }

private:
    const std::string* find(std::string_view key) {
        used_.emplace_back(key);
        const auto it = given_.find(std::string(key));
        return it == given_.end() ? nullptr : &it->second;
    }
    const std::string& name_;
    const std::map<std::string, std::string>& given_;
    std::vector<std::string> used_;
};

// Prints every field as key -> text; a choice whose value has no name (an automatic default)
// prints nothing. Collects the keys' placeholders and alternative values on the way.
class Writer final : public PcFields {
public:
    std::vector<PcKey> keys;
    void integer(std::string_view key, int& value, std::string_view placeholder) override {
        keys.push_back({std::string(key), std::string(placeholder), std::to_string(value),
                        std::to_string(value + 1)});
    }
    void real(std::string_view key, double& value, std::string_view placeholder) override {
        keys.push_back({std::string(key), std::string(placeholder), format_real(value),
                        format_real(value != 0 ? value / 2 : 0.5)});
    }
    void choice(std::string_view key, int& value,
                std::initializer_list<std::pair<std::string_view, int>> names) override {
        choice_list(key, value, {names.begin(), names.end()});
    }
    void choice_list(std::string_view key, int& value,
                     const std::vector<std::pair<std::string_view, int>>& names) override {
        PcKey k{std::string(key), names_of(names, "|"), "", ""};
        for (size_t i = 0; i < names.size(); ++i)
            if (names[i].second == value) {
                k.value = std::string(names[i].first);
                k.other = std::string(names[(i + 1) % names.size()].first);
            }
        if (k.other.empty() && !names.empty()) k.other = std::string(names.front().first);
        keys.push_back(std::move(k));
    }
};

std::vector<PcKey> keys_of(const PreconditionerEntry& e, const PcOptions& options) {
    Writer w;
    if (e.fields) {
        PcOptions copy = options;
        e.fields(copy, w);
    }
    return w.keys;
}

// `name[:opt,...]` split into a lower-cased name and its key -> value texts.
struct SplitSpec {
    std::string name;
    std::map<std::string, std::string> options;
};

SplitSpec split_spec(std::string_view spec) {
    SplitSpec out;
    const auto colon = spec.find(':');
    const std::string_view name = trim(spec.substr(0, colon));
    MLC_CHECK(!name.empty(), "empty preconditioner name in spec '"
                                 << spec << "'; valid specs:" << preconditioner_usages());
    out.name = lower(name);
    if (colon == std::string_view::npos) return out;
    const PreconditionerEntry* entry = preconditioner_entry(out.name);
    std::string_view rest = spec.substr(colon + 1);
    MLC_CHECK(!trim(rest).empty(),
              "empty option list after ':' in preconditioner spec '" << spec << "'");
    while (true) {
        const auto comma = rest.find(',');
        const std::string_view tok = trim(rest.substr(0, comma));
        const auto eq = tok.find('=');
        std::string key, value;
        if (eq == std::string_view::npos) {
            MLC_CHECK(entry != nullptr && !entry->positional_key.empty(),
                      "option '" << tok << "' in preconditioner spec '" << spec
                                 << "' needs the form key=value; valid specs:"
                                 << preconditioner_usages());
            key = entry->positional_key;
            value = std::string(tok);
        } else {
            key = std::string(trim(tok.substr(0, eq)));
            value = std::string(trim(tok.substr(eq + 1)));
        }
        MLC_CHECK(!key.empty() && !value.empty(), "empty key or value in option '"
                                                      << tok << "' of preconditioner spec '" << spec
                                                      << "'");
        MLC_CHECK(out.options.emplace(key, value).second,
                  "option '" << key << "' given twice in preconditioner spec '" << spec << "'");
        if (comma == std::string_view::npos) break;
        rest = rest.substr(comma + 1);
    }
    return out;
}

} // namespace

std::vector<PcKey> PreconditionerEntry::keys() const {
    return keys_of(*this, defaults);
}

std::string PreconditionerEntry::usage() const {
    std::ostringstream os;
    os << name;
    if (!positional_key.empty()) {
        for (const PcKey& k : keys())
            if (k.name == positional_key) os << "[:" << k.placeholder << "] or " << name;
    }
    const std::vector<PcKey> k = keys();
    if (!k.empty()) {
        os << "[:";
        for (size_t i = 0; i < k.size(); ++i)
            os << (i ? "," : "") << k[i].name << "=" << k[i].placeholder;
        os << "]";
    }
    os << " (" << summary << ")";
    return os.str();
}

std::string PreconditionerEntry::distributed_reason(const PcOptions& options) const {
    if (!distributed)
        return "'" + name +
               "' has no distributed form (it needs the whole level on one process): run it on "
               "one process, or use mg or a preconditioner of the matrix alone (diag, ilu, sor, "
               "...) on several";
    return distributed(options);
}

const std::string& PcSpec::name() const {
    static const std::string none;
    return entry ? entry->name : none;
}

std::string PcSpec::text() const {
    if (entry == nullptr) return {};
    const std::vector<PcKey> mine = keys_of(*entry, options);
    const std::vector<PcKey> def = entry->keys();
    std::string out = entry->name;
    bool first = true;
    for (size_t i = 0; i < mine.size(); ++i) {
        if (mine[i].value.empty() || (i < def.size() && def[i].value == mine[i].value)) continue;
        out += first ? ":" : ",";
        first = false;
        if (mine[i].name != entry->positional_key) out += mine[i].name + "=";
        out += mine[i].value;
    }
    return out;
}

bool PcSpec::lattice_numbering() const {
    return entry != nullptr && entry->lattice_numbering && entry->lattice_numbering(options);
}

std::string PcSpec::distributed() const {
    MLC_CHECK(entry != nullptr, "an empty preconditioner spec");
    return entry->distributed_reason(options);
}

std::string PreconditionerEntry::dimension_reason(const PcOptions& options, int dim) const {
    MLC_CHECK(dim == 2 || dim == 3, "a level has 2 or 3 dimensions, found " << dim);
    return dimensions ? dimensions(options, dim) : std::string();
}

std::string PcSpec::dimension_reason(int dim) const {
    MLC_CHECK(entry != nullptr, "an empty preconditioner spec");
    return entry->dimension_reason(options, dim);
}

bool PcSpec::operator==(const PcSpec& other) const {
    if (entry != other.entry) return false;
    if (entry == nullptr) return true;
    const auto a = keys_of(*entry, options), b = keys_of(*entry, other.options);
    if (a.size() != b.size()) return false;
    for (size_t i = 0; i < a.size(); ++i)
        if (a[i].name != b[i].name || a[i].value != b[i].value) return false;
    return true;
}

std::ostream& operator<<(std::ostream& os, const PcSpec& spec) {
    return os << spec.text();
}

PcSpec parse_pc(std::string_view text) {
    const SplitSpec s = split_spec(text);
    const PreconditionerEntry* entry = preconditioner_entry(s.name);
    MLC_CHECK(entry != nullptr, "unknown preconditioner '"
                                    << s.name << "' in spec '" << text
                                    << "'; valid specs:" << preconditioner_usages());
    PcSpec out{entry, entry->defaults};
    Reader r(entry->name, s.options);
    if (entry->fields) entry->fields(out.options, r);
    r.finish();
    return out;
}

const PreconditionerEntry* preconditioner_entry(std::string_view name) {
    for (const auto& e : preconditioner_registry())
        if (e.name == name) return &e;
    return nullptr;
}

std::string preconditioner_names(std::string_view separator) {
    std::string out;
    for (const auto& e : preconditioner_registry())
        out += (out.empty() ? "" : std::string(separator)) + e.name;
    return out;
}

std::string preconditioner_usages() {
    std::string out;
    for (const auto& e : preconditioner_registry())
        out += "\n  " + e.usage();
    return out;
}

} // namespace mlc::solvers
