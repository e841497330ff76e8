// Journals of finished work (format in journal.hpp).

#include "engine/journal.hpp"

#include <fstream>
#include <limits>

#include "engine/setup.hpp"

namespace voussoir {

nlohmann::json hinges_record(const std::vector<Hinge>& hinges) {
  nlohmann::json out = nlohmann::json::array();
  for (const Hinge& h : hinges)
    out.push_back({h.joint, h.block_a, h.block_b, h.kind, h.side, h.position_deg, h.x, h.y,
                   h.opening, h.slip});
  return out;
}

std::vector<Hinge> hinges_from_record(const nlohmann::json& record) {
  auto num = [](const nlohmann::json& v) {
    return v.is_null() ? std::numeric_limits<double>::quiet_NaN() : v.get<double>();
  };
  std::vector<Hinge> out;
  for (const auto& h : record)
    out.push_back(
        Hinge{h[0], h[1], h[2], h[3], h[4], num(h[5]), num(h[6]), num(h[7]), num(h[8]), num(h[9])});
  return out;
}

Journal::Journal(const std::string& path, const std::string& print) : path_(path) {
  if (path_.empty()) return;
  std::ifstream in(path_);
  std::string line;
  if (in && std::getline(in, line)) {
    const auto head = nlohmann::json::parse(line, nullptr, false);
    if (head.is_discarded() || !head.is_object() || head.value("fingerprint", "") != print)
      throw RunError("journal " + path_ +
                     " belongs to another deck or settings (fingerprint differs): remove it "
                     "or give another --resume file");
    while (std::getline(in, line)) {
      auto j = nlohmann::json::parse(line, nullptr, false);
      if (j.is_discarded()) break;  // a line cut by the kill: its work is done again
      records_.push_back(std::move(j));
    }
    in.close();
  }
  // (Re)written: the header and the whole records, without a possibly cut last line.
  std::ofstream out(path_, std::ios::trunc);
  if (!out) throw RunError("cannot write the journal " + path_);
  out << nlohmann::json{{"fingerprint", print}}.dump() << '\n';
  for (const nlohmann::json& r : records_) out << r.dump() << '\n';
}

void Journal::append(const nlohmann::json& record) {
  if (path_.empty()) return;
  std::ofstream out(path_, std::ios::app);
  out << record.dump() << '\n';
  out.flush();
}

}  // namespace voussoir
