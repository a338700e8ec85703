// SPDX-License-Identifier: MIT
#include "llsf/comm/proto_library.h"

#include <google/protobuf/compiler/importer.h>
#include <google/protobuf/descriptor.h>
#include <google/protobuf/dynamic_message.h>
#include <google/protobuf/stubs/logging.h>

#include <algorithm>
#include <filesystem>

#include "llsf/comm/registry.h"
#include "llsf/core/error.h"

namespace llsf::comm {

namespace pb = google::protobuf;

namespace {

// Collects the parser's errors as "dir/file.proto:LINE:COLUMN: message".
class Errors final : public pb::compiler::MultiFileErrorCollector {
 public:
  explicit Errors(std::string dir) : dir_(std::move(dir)) {}
  void AddError(const std::string& file, int line, int column,
                const std::string& message) override {
    if (!text_.empty()) text_ += '\n';
    text_ += (std::filesystem::path(dir_) / file).string() + ":" + std::to_string(line + 1) + ":" +
             std::to_string(column + 1) + ": " + message;
  }
  const std::string& text() const { return text_; }

 private:
  std::string dir_;
  std::string text_;
};

// One directory's parser: its source tree is the directory alone.
struct DirImporter {
  explicit DirImporter(const std::string& dir) : errors(dir), importer(&tree, &errors) {
    tree.MapPath("", dir);
  }
  pb::compiler::DiskSourceTree tree;
  Errors errors;
  pb::compiler::Importer importer;
};

// Why the agent's type `d` and llsfsim's generated type `g` of the same name differ ("" if
// every field of `d` is in `g` with its number, name, type and label).
std::string difference(const pb::Descriptor* d, const pb::Descriptor* g) {
  for (int i = 0; i < d->field_count(); ++i) {
    const pb::FieldDescriptor* f = d->field(i);
    const pb::FieldDescriptor* h = g->FindFieldByNumber(f->number());
    if (h == nullptr) return "field " + f->name() + " = " + std::to_string(f->number()) + " is new";
    if (h->name() != f->name() || h->type() != f->type() || h->label() != f->label()) {
      return "field " + std::to_string(f->number()) + " is " + f->name() + " (" + f->type_name() +
             ") there, " + h->name() + " (" + h->type_name() + ") in llsfsim";
    }
  }
  return {};  // llsfsim's type may have more fields (a later refbox's): the agent reads its own
}

}  // namespace

struct ProtoLibrary::Impl {
  std::vector<std::unique_ptr<DirImporter>> importers;
  // Declared after the importers: destroyed first (its prototypes point into their pools).
  std::unique_ptr<pb::DynamicMessageFactory> factory;
};

ProtoLibrary::ProtoLibrary() : impl_(std::make_unique<Impl>()) {}
ProtoLibrary::~ProtoLibrary() {
  impl_->factory.reset();
  impl_->importers.clear();
}

std::shared_ptr<const ProtoLibrary> ProtoLibrary::load(const std::vector<std::string>& dirs) {
  std::shared_ptr<ProtoLibrary> lib(new ProtoLibrary());
  Impl& impl = *lib->impl_;
  // The parser logs warnings to stderr (a file without a `syntax` line, as the 2013 files are,
  // defaults to proto2); errors reach the collector.
  const pb::LogSilencer quiet;
  std::vector<const pb::FileDescriptor*> built;  // the directories' files, in name order
  for (const std::string& dir : dirs) {
    std::vector<std::string> files;
    std::error_code ec;
    for (std::filesystem::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
      if (it->path().extension() == ".proto") files.push_back(it->path().filename().string());
    }
    if (ec) throw core::ConfigError(dir + ": cannot list the .proto files: " + ec.message());
    std::sort(files.begin(), files.end());
    impl.importers.push_back(std::make_unique<DirImporter>(dir));
    DirImporter& d = *impl.importers.back();
    for (const std::string& f : files) {
      if (const pb::FileDescriptor* fd = d.importer.Import(f)) built.push_back(fd);
    }
    if (!d.errors.text().empty()) throw core::ConfigError(d.errors.text());
  }
  impl.factory = std::make_unique<pb::DynamicMessageFactory>();
  const pb::DescriptorPool* generated = pb::DescriptorPool::generated_pool();
  for (const pb::FileDescriptor* fd : built) {
    for (int i = 0; i < fd->message_type_count(); ++i) {
      const pb::Descriptor* m = fd->message_type(i);
      lib->names_.push_back(m->full_name());
      if (const pb::Descriptor* g = generated->FindMessageTypeByName(m->full_name())) {
        if (const std::string why = difference(m, g); !why.empty()) {
          throw core::ConfigError(fd->name() + ": " + m->full_name() +
                                  " differs from llsfsim's type of that name: " + why);
        }
        continue;  // the generated type stands for it
      }
      const pb::EnumDescriptor* ct = m->FindEnumTypeByName("CompType");
      const pb::EnumValueDescriptor* comp = ct ? ct->FindValueByName("COMP_ID") : nullptr;
      const pb::EnumValueDescriptor* type = ct ? ct->FindValueByName("MSG_TYPE") : nullptr;
      if (comp == nullptr || type == nullptr) continue;  // not sent on its own
      lib->types_.emplace_back(MessageKey{comp->number(), type->number()},
                               impl.factory->GetPrototype(m));
    }
  }
  std::sort(lib->names_.begin(), lib->names_.end());
  return lib;
}

void ProtoLibrary::register_in(MessageRegistry& registry) const {
  for (const auto& [key, proto] : types_) {
    if (const pb::Message* taken = registry.prototype(key)) {
      if (taken == proto) continue;
      throw core::ConfigError(
          "the agent's message " + proto->GetDescriptor()->full_name() + " (" +
          std::to_string(key.component_id) + ", " + std::to_string(key.msg_type) +
          ") collides with " + taken->GetDescriptor()->full_name() +
          " at the same component id and type (radio.lock_messages: 2013 puts llsfsim's lock "
          "messages there; a Fawkes-style agent with its own lock messages needs the default, "
          "docs/fawkes.md)");
    }
    registry.add(key, *proto);
  }
}

}  // namespace llsf::comm
