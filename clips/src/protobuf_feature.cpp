// SPDX-License-Identifier: MIT
// Protobuf feature: received messages as protobuf-msg facts and the pb-* functions over protobuf
// reflection, for every message type of the comm::MessageRegistry. Messages reach CLIPS as
// EXTERNAL-ADDRESS values that point into an owned pool; every function checks that a pointer is
// in the pool, so a stale pointer is a runtime error and never a crash.
//
// Lifetimes: (pb-create) messages live until (pb-destroy); received messages until the end of the
// cycle in which their protobuf-msg fact was asserted; nested-message pointers (from
// pb-field-value / pb-field-list) until the end of the cycle or until their root is destroyed.
#include <google/protobuf/descriptor.h>
#include <google/protobuf/message.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cstdint>
#include <optional>
#include <unordered_map>

#include "feature.h"
#include "llsf/comm/registry.h"
#include "message_use.h"

namespace llsf::clips::detail {
namespace {

using google::protobuf::Descriptor;
using google::protobuf::FieldDescriptor;
using google::protobuf::Message;
using google::protobuf::Reflection;

constexpr std::int64_t kNsPerSec = 1'000'000'000;

class ProtobufFeature final : public Feature {
 public:
  explicit ProtobufFeature(HostState& s) : s_(s) {}
  ~ProtobufFeature() override { s_.live_messages = 0; }

  void define(Environment& env) override {
    env.define_function("pb-create", "11k", [this](Args& a) { return create(a); });
    env.define_function("pb-destroy", "11a", [this](Args& a) {
      Entry* e = lookup(a, 0);
      if (e != nullptr && e->kind != Kind::kView) destroy(e->root);
      return Value{};
    });
    env.define_function("pb-set-field", "33*", [this](Args& a) { return set(a, false); });
    env.define_function("pb-add-list", "33*", [this](Args& a) { return set(a, true); });
    env.define_function("pb-field-value", "22*", [this](Args& a) {
      Message* m = nullptr;
      if (s_.config.fawkes) {
        // As Fawkes' pb-field-value: the symbol DOES-NOT-EXIST for a field the type lacks,
        // NOT-SET for a scalar field that is not set.
        Entry* e = lookup(a, 0);
        std::string_view name;
        if (e == nullptr || !a.text(1, name)) return Value::symbol("INVALID-MESSAGE");
        m = e->message;
        const FieldDescriptor* f = find_field(m->GetDescriptor(), name);
        if (f == nullptr) {
          s_.log(LogLevel::kWarn, "pb-field-value: " + m->GetTypeName() + " has no field " +
                                      std::string(name) + ": DOES-NOT-EXIST");
          return Value::symbol("DOES-NOT-EXIST");
        }
        if (f->is_repeated()) {
          a.env().error(a.function(), f->name() + " is repeated: use pb-field-list");
          return Value::boolean(false);
        }
        if (f->cpp_type() != FieldDescriptor::CPPTYPE_MESSAGE &&
            !m->GetReflection()->HasField(*m, f))
          return Value::symbol("NOT-SET");
        return_field(a, *m, f);
        return Value{};
      }
      const FieldDescriptor* f = field(a, m);
      if (f == nullptr) return Value::boolean(false);
      if (f->is_repeated()) {
        a.env().error(a.function(), f->name() + " is repeated: use pb-field-list");
        return Value::boolean(false);
      }
      return_field(a, *m, f);
      return Value{};
    });
    env.define_function("pb-field-list", "22*", [this](Args& a) {
      Message* m = nullptr;
      const FieldDescriptor* f = field(a, m);
      if (f == nullptr) return Value::multifield({});
      std::vector<Value> items;
      if (f->is_repeated()) {
        const int n = m->GetReflection()->FieldSize(*m, f);
        items.reserve(static_cast<std::size_t>(n));
        for (int i = 0; i < n; ++i) items.push_back(get(*m, f, i));
      } else if (m->GetReflection()->HasField(*m, f)) {
        items.push_back(get(*m, f, -1));
      }
      return Value::multifield(std::move(items));
    });
    env.define_function("pb-has-field", "22*", [this](Args& a) {
      Message* m = nullptr;
      const FieldDescriptor* f = field(a, m);
      if (f == nullptr) return Value::boolean(false);
      const Reflection* r = m->GetReflection();
      return Value::boolean(f->is_repeated() ? r->FieldSize(*m, f) > 0 : r->HasField(*m, f));
    });
    env.define_function("pb-field-is-list", "22*", [this](Args& a) {
      Message* m = nullptr;
      const FieldDescriptor* f = field(a, m);
      return Value::boolean(f != nullptr && f->is_repeated());
    });
    env.define_function("pb-field-names", "11a", [this](Args& a) {
      Entry* e = lookup(a, 0);
      std::vector<Value> names;
      if (e != nullptr) {
        const Descriptor* d = e->message->GetDescriptor();
        for (int i = 0; i < d->field_count(); ++i)
          names.push_back(Value::string(d->field(i)->name()));
      }
      return Value::multifield(std::move(names));
    });
    env.define_function("pb-tostring", "11a", [this](Args& a) {
      Entry* e = lookup(a, 0);
      return e == nullptr ? Value::boolean(false) : Value::string(e->message->ShortDebugString());
    });
    env.define_function("pb-unchanged", "2**", [this](Args& a) { return unchanged(a); });
    // (pb-broadcast ?msg), or (pb-broadcast ?peer-id ?msg) for a peer of pb-peer-create: on the
    // robot's radio. A Fawkes-style agent broadcasts only once its peer is enabled.
    env.define_function("pb-broadcast", "12*", [this](Args& a) {
      if (a.count() == 2 && !known_peer(a)) return Value{};
      Entry* e = lookup(a, a.count() - 1);
      if (e == nullptr || !complete(a, *e->message)) return Value{};
      if (s_.config.fawkes && !s_.peer_enabled) {
        s_.log(LogLevel::kWarn, "pb-broadcast: no peer enabled (pb-peer-enable): " +
                                    e->message->GetTypeName() + " not sent");
        return Value{};
      }
      if (s_.io.broadcast) s_.io.broadcast(*e->message);
      return Value{};
    });
    // The radio peer (Fawkes' ProtobufBroadcastPeer): the robot's team radio, whatever the
    // address and ports (the simulated radio has no addresses; docs/fawkes.md).
    env.define_function("pb-peer-enable", "23*", [this](Args& a) {
      if (!peer_arguments(a)) return Value{};
      s_.peer_enabled = true;
      return Value{};
    });
    env.define_function("pb-peer-disable", "00", [this](Args&) {
      s_.peer_enabled = false;
      return Value{};
    });
    // (pb-peer-create address port [recv-port]): the peer's id (later Fawkes versions).
    env.define_function("pb-peer-create", "23*", [this](Args& a) {
      if (!peer_arguments(a)) return Value::boolean(false);
      s_.peer_enabled = true;
      return Value::integer_value(kPeerId);
    });
    env.define_function("pb-peer-destroy", "11i", [this](Args& a) {
      if (known_peer(a)) s_.peer_enabled = false;
      return Value{};
    });
    // (pb-server-enable port) / (pb-server-disable): Fawkes' stream server, which clients
    // connected to ((protobuf-server-client-connected ID HOST PORT) facts). Nothing in a game
    // connects to a robot (the refbox and the other robots talk on the radio), so no client
    // ever does: the server is accepted, and stays silent (docs/fawkes.md).
    env.define_function("pb-server-enable", "11i", [this](Args& a) {
      std::int64_t port = 0;
      if (!a.integer(0, port) || port <= 0 || port > 65535) {
        a.env().error(a.function(), "expects a port (1..65535)");
        return Value{};
      }
      server_port_ = port;
      s_.log(LogLevel::kDebug, "pb-server-enable: stream server on port " + std::to_string(port) +
                                   " (no client connects in a simulated game)");
      return Value{};
    });
    env.define_function("pb-server-disable", "00", [this](Args&) {
      if (server_port_ != 0)
        s_.log(LogLevel::kDebug,
               "pb-server-disable: stream server on port " + std::to_string(server_port_) + " off");
      server_port_ = 0;
      return Value{};
    });
    // (pb-connect host port): a stream client to the game's server, the refbox; its id, and
    // (protobuf-client-connected ID). (pb-send ID ?msg) sends to it, (pb-disconnect ID) ends it.
    env.define_function("pb-connect", "22*", [this, &env](Args& a) {
      std::string_view host;
      std::int64_t port = 0;
      if (!a.text(0, host) || !a.integer(1, port) || port <= 0 || port > 65535) {
        a.env().error(a.function(), "expects a host name and a port (1..65535)");
        return Value::boolean(false);
      }
      const std::int64_t id = ++last_client_;
      clients_.push_back(id);
      env.assert_string("(protobuf-client-connected " + std::to_string(id) + ")");
      return Value::integer_value(id);
    });
    env.define_function("pb-disconnect", "11i", [this, &env](Args& a) {
      std::int64_t id = 0;
      a.integer(0, id);
      if (std::erase(clients_, id) == 0) return Value{};
      env.assert_string("(protobuf-client-disconnected " + std::to_string(id) + ")");
      return Value{};
    });
    env.define_function("pb-send", "22*", [this](Args& a) {
      std::int64_t id = 0;
      if (!a.integer(0, id) || std::find(clients_.begin(), clients_.end(), id) == clients_.end()) {
        a.env().error(a.function(), "no connection " + a.view(0).to_value().to_string() +
                                        " (pb-connect returns the id)");
        return Value{};
      }
      Entry* e = lookup(a, 1);
      if (e == nullptr || !complete(a, *e->message)) return Value{};
      if (s_.io.send) s_.io.send(*e->message);
      return Value{};
    });
    // (pb-ref ?msg): keeps a received message beyond its cycle, until (pb-destroy ?msg).
    env.define_function("pb-ref", "11a", [this](Args& a) {
      Entry* e = lookup(a, 0);
      if (e == nullptr) return Value::boolean(false);
      if (e->kind == Kind::kReceived) e->kind = Kind::kCreated;
      return Value::external(e->message);
    });
    env.define_function("pb-register-type", "11k", [this](Args& a) {
      std::string_view type;
      a.text(0, type);
      return Value::boolean(s_.io.messages != nullptr && prototype(type) != nullptr);
    });
    // (pb-field-type ?msg field): DOUBLE, FLOAT, INT64, UINT64, INT32, FIXED64, FIXED32, BOOL,
    // STRING, MESSAGE, BYTES, UINT32, ENUM, SFIXED32, SFIXED64, SINT32, SINT64 (protobuf's names).
    env.define_function("pb-field-type", "22*", [this](Args& a) {
      Message* m = nullptr;
      const FieldDescriptor* f = field(a, m);
      if (f == nullptr) return Value::symbol("INVALID-MESSAGE");
      std::string t = FieldDescriptor::TypeName(f->type());
      for (char& c : t) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
      return Value::symbol(t);
    });
    // (pb-field-label ?msg field): OPTIONAL, REQUIRED or REPEATED.
    env.define_function("pb-field-label", "22*", [this](Args& a) {
      Message* m = nullptr;
      const FieldDescriptor* f = field(a, m);
      if (f == nullptr) return Value::symbol("INVALID-MESSAGE");
      return Value::symbol(f->is_repeated()   ? "REPEATED"
                           : f->is_required() ? "REQUIRED"
                                              : "OPTIONAL");
    });
  }

  void bind(Environment& env) override {
    msg_ = env.find_template("protobuf-msg");
    slot_type_ = msg_.slot_index("type");
    slot_comp_ = msg_.slot_index("comp-id");
    slot_msg_type_ = msg_.slot_index("msg-type");
    slot_from_ = msg_.slot_index("rcvd-from");
    slot_at_ = msg_.slot_index("rcvd-at");
    slot_client_id_ = msg_.slot_index("client-id");
    slot_ptr_ = msg_.slot_index("ptr");
    values_.resize(msg_.slots.size());
  }

  void after_reset(Environment& env) override {
    for (auto& h : facts_) env.release(h);
    facts_.clear();
    last_.clear();  // the facts a skipped message would have made are gone too
  }

  void before_run(Environment& env) override {
    // Which types can match a rule (again after code was loaded): the others make no fact.
    if (env.code_version() != code_version_) {
      code_version_ = env.code_version();
      std::vector<std::string> texts;
      matched_ = env.construct_texts(texts) ? matched_message_types(texts) : std::nullopt;
      wanted_.clear();
    }
    // The slot values are rewritten in place (their strings and lists keep their capacity): no
    // allocation per message once the longest type name and peer name have been seen.
    // A Fawkes-style agent hears nothing before it enabled its peer (Fawkes' peer was not
    // there to receive).
    if (s_.config.fawkes && !s_.peer_enabled) s_.inbox.clear();
    for (auto& r : s_.inbox) {
      Message* m = r.message.get();
      if (matched_ && !wanted(m->GetDescriptor())) continue;
      add(std::move(r.message), Kind::kReceived, m);
      set_text(slot_type_, Value::Type::kString, m->GetDescriptor()->full_name());
      std::optional<comm::MessageKey> key;
      if (s_.io.messages != nullptr) key = s_.io.messages->key_of(*m);
      Value& comp = values_[static_cast<std::size_t>(slot_comp_)];
      Value& msg_type = values_[static_cast<std::size_t>(slot_msg_type_)];
      comp.type = msg_type.type = key ? Value::Type::kInteger : Value::Type::kVoid;  // or default
      if (key) {
        comp.integer = key->component_id;
        msg_type.integer = key->msg_type;
      }
      Value& from = values_[static_cast<std::size_t>(slot_from_)];
      from.type = Value::Type::kMultifield;
      from.items.resize(2);
      from.items[0].type = Value::Type::kString;
      from.items[0].text.assign(r.from);
      from.items[1] = Value::integer_value(r.from_id);
      Value& at = values_[static_cast<std::size_t>(slot_at_)];
      at.type = Value::Type::kMultifield;
      at.items.resize(2);
      at.items[0] = Value::integer_value(r.at.ns() / kNsPerSec);
      at.items[1] = Value::integer_value((r.at.ns() % kNsPerSec) / 1000);
      values_[static_cast<std::size_t>(slot_client_id_)] = Value::integer_value(r.from_id);
      values_[static_cast<std::size_t>(slot_ptr_)] = Value::external(m);
      facts_.push_back(env.assert_fact(msg_, values_));
    }
    s_.inbox.clear();
  }

  // Unconsumed protobuf-msg facts go, their messages are freed, nested pointers expire.
  void after_run(Environment& env) override {
    for (auto& h : facts_) env.retract(h);
    facts_.clear();
    // Received messages (unless pb-ref kept them) and views end with the run. Only those are
    // looked at: an agent that never destroys what it creates (the 2013 agent's reports) would
    // otherwise make every run cost as much as all its messages.
    for (const void* key : transient_) {
      auto it = entries_.find(key);
      if (it != entries_.end() && it->second.kind != Kind::kCreated) entries_.erase(it);
    }
    transient_.clear();
    s_.live_messages = static_cast<int>(entries_.size());
  }

 private:
  static constexpr std::int64_t kPeerId = 1;  // the one radio peer (pb-peer-create)

  // (pb-peer-enable address send-port [recv-port]): an address and ports.
  static bool peer_arguments(Args& a) {
    std::string_view address;
    std::int64_t port = 0;
    bool ok = a.text(0, address) && a.integer(1, port) && port > 0 && port <= 65535;
    if (ok && a.count() == 3) ok = a.integer(2, port) && port >= 0 && port <= 65535;
    if (!ok) a.env().error(a.function(), "expects an address and one or two ports (1..65535)");
    return ok;
  }

  bool known_peer(Args& a) {
    std::int64_t id = 0;
    if (a.integer(0, id) && id == kPeerId && s_.peer_enabled) return true;
    a.env().error(a.function(), "no peer " + a.view(0).to_value().to_string() +
                                    " (pb-peer-create returns the id)");
    return false;
  }

  static bool complete(Args& a, const Message& m) {
    if (m.IsInitialized()) return true;
    a.env().error(a.function(),
                  m.GetTypeName() + " lacks required fields: " + m.InitializationErrorString());
    return false;
  }

  // Whether a message type can match a rule (matched_ set): decided once per type by name, then
  // found by its descriptor (a handful of types: a linear scan of pointers).
  bool wanted(const Descriptor* d) {
    for (const auto& [type, yes] : wanted_)
      if (type == d) return yes;
    const bool yes = matched_->contains(d->full_name());
    wanted_.emplace_back(d, yes);
    return yes;
  }

  // A text slot value, reusing the string's capacity.
  void set_text(int slot, Value::Type type, const std::string& text) {
    Value& v = values_[static_cast<std::size_t>(slot)];
    v.type = type;
    v.text.assign(text);
  }

  enum class Kind : std::uint8_t { kCreated, kReceived, kView };
  struct Entry {
    Kind kind;
    Message* message;
    const Message* root;             // the owning top-level message
    std::unique_ptr<Message> owned;  // for kCreated and kReceived, and a nested field's copy
  };

  void add(std::unique_ptr<Message> m, Kind kind, Message* raw) {
    Entry e{kind, raw, raw, std::move(m)};
    entries_.emplace(raw, std::move(e));
    if (kind != Kind::kCreated) transient_.push_back(raw);
    s_.live_messages = static_cast<int>(entries_.size());
  }

  void destroy(const Message* root) {
    // (views are transient: only those of this run can be left)
    for (const void* key : transient_) {
      auto it = entries_.find(key);
      if (it != entries_.end() && it->second.root == root && it->second.kind == Kind::kView) {
        entries_.erase(it);
      }
    }
    entries_.erase(root);
    s_.live_messages = static_cast<int>(entries_.size());
  }

  Entry* lookup(Args& a, int i) {
    void* p = nullptr;
    if (!a.address(i, p)) {
      a.env().error(a.function(), "argument " + std::to_string(i + 1) + " must be a message");
      return nullptr;
    }
    auto it = entries_.find(p);
    if (it == entries_.end()) {
      a.env().error(a.function(),
                    "not a live message (destroyed, or received in an earlier cycle)");
      return nullptr;
    }
    return &it->second;
  }

  // The message (argument 1) and its field (argument 2, a string or symbol).
  const FieldDescriptor* field(Args& a, Message*& m) {
    Entry* e = lookup(a, 0);
    if (e == nullptr) return nullptr;
    std::string_view name;
    if (!a.text(1, name)) {
      a.env().error(a.function(), "the field name must be a string or symbol");
      return nullptr;
    }
    m = e->message;
    const FieldDescriptor* f = find_field(m->GetDescriptor(), name);
    if (f == nullptr)
      a.env().error(a.function(), m->GetTypeName() + " has no field " + std::string(name));
    return f;
  }

  // FindFieldByName with a small cache: field names are CLIPS symbols whose text stays at one
  // address while the rule that names them exists; a hit is checked against the field's name, so
  // a reused address can never return the wrong field.
  const FieldDescriptor* find_field(const Descriptor* d, std::string_view name) {
    const auto key =
        reinterpret_cast<std::uintptr_t>(d) ^ reinterpret_cast<std::uintptr_t>(name.data());
    FieldCacheEntry& c = field_cache_[(key >> 3) % kFieldCacheSize];
    if (c.descriptor == d && c.name == name.data() && c.field != nullptr && c.field->name() == name)
      return c.field;
    const FieldDescriptor* f = d->FindFieldByName(std::string(name));
    if (f != nullptr) c = {d, name.data(), f};
    return f;
  }

  // (pb-unchanged ?m ?key [FIELD...]): TRUE when ?m, apart from the named fields, has the same
  // type and content (the same serialised bytes) as the message last given with ?key; remembers
  // ?m for ?key either way. For periodic status messages: a rule can skip one that repeats the
  // last from the same sender.
  Value unchanged(Args& a) {
    Entry* e = lookup(a, 0);
    if (e == nullptr) return Value::boolean(false);
    const ArgView key = a.view(1);
    std::string& k = key_scratch_;
    switch (key.type) {
      case Value::Type::kSymbol:
      case Value::Type::kString:
        k.assign(key.text);
        break;
      case Value::Type::kInteger:
        k = std::to_string(key.integer);
        break;
      default:
        a.env().error(a.function(), "the key (argument 2) must be a symbol, string or integer");
        return Value::boolean(false);
    }
    Message* m = e->message;
    const Descriptor* d = m->GetDescriptor();
    std::vector<const FieldDescriptor*>& left_out = fields_scratch_;
    left_out.clear();
    for (int i = 2; i < a.count(); ++i) {
      std::string_view name;
      if (!a.text(i, name)) {
        a.env().error(a.function(), "argument " + std::to_string(i + 1) +
                                        " must be a field name (a string or symbol)");
        return Value::boolean(false);
      }
      const FieldDescriptor* f = find_field(d, name);
      if (f == nullptr) {
        a.env().error(a.function(), m->GetTypeName() + " has no field " + std::string(name));
        return Value::boolean(false);
      }
      if (std::find(left_out.begin(), left_out.end(), f) == left_out.end()) left_out.push_back(f);
    }
    // The left-out fields are swapped into an empty message of the type while ?m is serialised
    // and swapped back (a swap moves nested and repeated fields without copying them).
    std::unique_ptr<Message>& aside = scratch_[d];
    const bool swap = !left_out.empty();
    if (swap) {
      if (!aside) aside.reset(m->New());
      m->GetReflection()->SwapFields(m, aside.get(), left_out);
    }
    bytes_scratch_.clear();
    m->SerializePartialToString(&bytes_scratch_);
    if (swap) {
      m->GetReflection()->SwapFields(m, aside.get(), left_out);
      aside->Clear();
    }
    auto it = last_.find(k);
    if (it == last_.end()) {
      if (last_.size() >= kMaxUnchangedKeys) {
        a.env().error(a.function(), "more than " + std::to_string(kMaxUnchangedKeys) +
                                        " keys: use one per sender and message type");
        return Value::boolean(false);
      }
      last_.emplace(k, Last{d, bytes_scratch_});
      return Value::boolean(false);
    }
    const bool same = it->second.type == d && it->second.bytes == bytes_scratch_;
    if (!same) {
      it->second.type = d;
      it->second.bytes.swap(bytes_scratch_);
    }
    return Value::boolean(same);
  }

  Value create(Args& a) {
    std::string_view type;
    a.text(0, type);
    if (s_.io.messages == nullptr) {
      a.env().error(a.function(), "this agent has no message registry");
      return Value::boolean(false);
    }
    const Message* proto = prototype(type);
    if (proto == nullptr) {
      a.env().error(a.function(), "message type " + std::string(type) + " is not registered");
      return Value::boolean(false);
    }
    std::unique_ptr<Message> m(proto->New());
    Message* raw = m.get();
    add(std::move(m), Kind::kCreated, raw);
    return Value::external(raw);
  }

  const Message* prototype(std::string_view type) {
    const comm::MessageRegistry& reg = *s_.io.messages;
    if (static_cast<int>(by_name_.size()) - nested_types_ != reg.size()) {
      nested_types_ = 0;
      by_name_.clear();
      for (int i = 0; i < reg.size(); ++i) by_name_[reg.name_at(i)] = reg.prototype(reg.key_at(i));
    }
    const std::string name(type);
    if (auto it = by_name_.find(name); it != by_name_.end()) return it->second;
    // Types used inside registered messages (e.g. llsf_agent_msgs.MachineState) are not in the
    // registry: take them from protobuf's generated pool, once a registered type is loaded.
    const Descriptor* d =
        google::protobuf::DescriptorPool::generated_pool()->FindMessageTypeByName(name);
    const Message* proto = nullptr;
    if (d != nullptr) {
      proto = google::protobuf::MessageFactory::generated_factory()->GetPrototype(d);
    } else {
      // Or a type of an agent's own .proto files (comm::ProtoLibrary) that is used inside a
      // registered one: from that one's pool and factory.
      for (int i = 0; i < reg.size() && proto == nullptr; ++i) {
        const Message* p = reg.prototype(reg.key_at(i));
        const google::protobuf::DescriptorPool* pool = p->GetDescriptor()->file()->pool();
        if (pool == google::protobuf::DescriptorPool::generated_pool()) continue;
        if (const Descriptor* own = pool->FindMessageTypeByName(name))
          proto = p->GetReflection()->GetMessageFactory()->GetPrototype(own);
      }
    }
    if (proto == nullptr) return nullptr;
    by_name_[name] = proto;
    nested_types_ += 1;
    return proto;
  }

  Value get(Message& m, const FieldDescriptor* f, int index) {
    const Reflection* r = m.GetReflection();
    const bool rep = index >= 0;
    switch (f->cpp_type()) {
      case FieldDescriptor::CPPTYPE_INT32:
        return Value::integer_value(rep ? r->GetRepeatedInt32(m, f, index) : r->GetInt32(m, f));
      case FieldDescriptor::CPPTYPE_INT64:
        return Value::integer_value(rep ? r->GetRepeatedInt64(m, f, index) : r->GetInt64(m, f));
      case FieldDescriptor::CPPTYPE_UINT32:
        return Value::integer_value(rep ? r->GetRepeatedUInt32(m, f, index) : r->GetUInt32(m, f));
      case FieldDescriptor::CPPTYPE_UINT64:
        return Value::integer_value(static_cast<std::int64_t>(
            rep ? r->GetRepeatedUInt64(m, f, index) : r->GetUInt64(m, f)));
      case FieldDescriptor::CPPTYPE_DOUBLE:
        return Value::float_value(rep ? r->GetRepeatedDouble(m, f, index) : r->GetDouble(m, f));
      case FieldDescriptor::CPPTYPE_FLOAT:
        return Value::float_value(rep ? r->GetRepeatedFloat(m, f, index) : r->GetFloat(m, f));
      case FieldDescriptor::CPPTYPE_BOOL:
        return Value::boolean(rep ? r->GetRepeatedBool(m, f, index) : r->GetBool(m, f));
      case FieldDescriptor::CPPTYPE_ENUM:
        return Value::symbol((rep ? r->GetRepeatedEnum(m, f, index) : r->GetEnum(m, f))->name());
      case FieldDescriptor::CPPTYPE_STRING:
        return Value::string(rep ? r->GetRepeatedString(m, f, index) : r->GetString(m, f));
      case FieldDescriptor::CPPTYPE_MESSAGE: {
        auto root_it = entries_.find(&m);
        const Message* root = root_it != entries_.end() ? root_it->second.root : &m;
        // A field that is not set reads as a new empty message of its type, and a Fawkes-style
        // agent always gets a copy (as Fawkes' pb-field-value made one): the agent may fill it
        // and set it with pb-set-field. The copy lives as the views do (to the end of the cycle
        // or its root's pb-destroy). llsfsim's agents read a set field in place (a view).
        const bool set = rep || r->HasField(m, f);
        if (!set || s_.config.fawkes) {
          const Message& from = rep ? r->GetRepeatedMessage(m, f, index) : r->GetMessage(m, f);
          std::unique_ptr<Message> copy(from.New());
          if (set) copy->CopyFrom(from);
          Message* raw = copy.get();
          entries_.emplace(raw, Entry{Kind::kView, raw, root, std::move(copy)});
          transient_.push_back(raw);
          s_.live_messages = static_cast<int>(entries_.size());
          return Value::external(raw);
        }
        Message* sub = rep ? r->MutableRepeatedMessage(&m, f, index) : r->MutableMessage(&m, f);
        auto [it, inserted] = entries_.try_emplace(sub, Entry{Kind::kView, sub, root, {}});
        if (inserted) transient_.push_back(sub);
        if (!inserted && it->second.kind == Kind::kView) it->second.root = root;
        s_.live_messages = static_cast<int>(entries_.size());
        return Value::external(sub);
      }
    }
    return {};
  }

  // pb-field-value's result, set directly (no Value in between; the same values as get()).
  void return_field(Args& a, Message& m, const FieldDescriptor* f) {
    const Reflection* r = m.GetReflection();
    switch (f->cpp_type()) {
      case FieldDescriptor::CPPTYPE_INT32:
        return a.return_integer(r->GetInt32(m, f));
      case FieldDescriptor::CPPTYPE_INT64:
        return a.return_integer(r->GetInt64(m, f));
      case FieldDescriptor::CPPTYPE_UINT32:
        return a.return_integer(r->GetUInt32(m, f));
      case FieldDescriptor::CPPTYPE_UINT64:
        return a.return_integer(static_cast<std::int64_t>(r->GetUInt64(m, f)));
      case FieldDescriptor::CPPTYPE_DOUBLE:
        return a.return_float(r->GetDouble(m, f));
      case FieldDescriptor::CPPTYPE_FLOAT:
        return a.return_float(r->GetFloat(m, f));
      case FieldDescriptor::CPPTYPE_BOOL:
        return a.return_boolean(r->GetBool(m, f));
      case FieldDescriptor::CPPTYPE_ENUM:
        return a.return_symbol(r->GetEnum(m, f)->name().c_str());
      case FieldDescriptor::CPPTYPE_STRING: {
        std::string scratch;
        return a.return_string(r->GetStringReference(m, f, &scratch).c_str());
      }
      case FieldDescriptor::CPPTYPE_MESSAGE:
        return a.return_external(get(m, f, -1).address);
    }
  }

  Value set(Args& a, bool add_to_list) {
    Message* m = nullptr;
    const FieldDescriptor* f = field(a, m);
    if (f == nullptr) return Value{};
    if (f->is_repeated() != add_to_list) {
      a.env().error(a.function(), f->name() + (add_to_list ? " is not repeated: use pb-set-field"
                                                           : " is repeated: use pb-add-list"));
      return Value{};
    }
    const Reflection* r = m->GetReflection();
    const ArgView v = a.view(2);  // read once: the argument's expression runs on every read
    auto fail = [&](const char* expected) {
      const std::string got = v.to_value().to_string();
      a.env().error(a.function(), f->full_name() + " expects " + expected + ", got " +
                                      (got.empty() ? "nothing" : got));
      return Value{};
    };
    switch (f->cpp_type()) {
      case FieldDescriptor::CPPTYPE_INT32:
      case FieldDescriptor::CPPTYPE_INT64:
      case FieldDescriptor::CPPTYPE_UINT32:
      case FieldDescriptor::CPPTYPE_UINT64: {
        if (!v.is_number()) return fail("an integer");
        const auto i =
            v.type == Value::Type::kInteger ? v.integer : static_cast<std::int64_t>(v.real);
        switch (f->cpp_type()) {
          case FieldDescriptor::CPPTYPE_INT32:
            add_to_list ? r->AddInt32(m, f, static_cast<std::int32_t>(i))
                        : r->SetInt32(m, f, static_cast<std::int32_t>(i));
            break;
          case FieldDescriptor::CPPTYPE_INT64:
            add_to_list ? r->AddInt64(m, f, i) : r->SetInt64(m, f, i);
            break;
          case FieldDescriptor::CPPTYPE_UINT32:
            if (i < 0) return fail("a non-negative integer");
            add_to_list ? r->AddUInt32(m, f, static_cast<std::uint32_t>(i))
                        : r->SetUInt32(m, f, static_cast<std::uint32_t>(i));
            break;
          default:
            if (i < 0) return fail("a non-negative integer");
            add_to_list ? r->AddUInt64(m, f, static_cast<std::uint64_t>(i))
                        : r->SetUInt64(m, f, static_cast<std::uint64_t>(i));
        }
        return Value{};
      }
      case FieldDescriptor::CPPTYPE_DOUBLE:
        if (!v.is_number()) return fail("a number");
        add_to_list ? r->AddDouble(m, f, v.number()) : r->SetDouble(m, f, v.number());
        return Value{};
      case FieldDescriptor::CPPTYPE_FLOAT:
        if (!v.is_number()) return fail("a number");
        add_to_list ? r->AddFloat(m, f, static_cast<float>(v.number()))
                    : r->SetFloat(m, f, static_cast<float>(v.number()));
        return Value{};
      case FieldDescriptor::CPPTYPE_BOOL: {
        bool b = false;
        if (v.is_symbol("TRUE") || v.is_symbol("true"))
          b = true;
        else if (v.is_symbol("FALSE") || v.is_symbol("false"))
          b = false;
        else if (v.type == Value::Type::kInteger)
          b = v.integer != 0;
        else
          return fail("TRUE or FALSE");
        add_to_list ? r->AddBool(m, f, b) : r->SetBool(m, f, b);
        return Value{};
      }
      case FieldDescriptor::CPPTYPE_ENUM: {
        const google::protobuf::EnumValueDescriptor* ev = nullptr;
        if (v.type == Value::Type::kSymbol || v.type == Value::Type::kString)
          ev = f->enum_type()->FindValueByName(std::string(v.text));
        else if (v.type == Value::Type::kInteger)
          ev = f->enum_type()->FindValueByNumber(static_cast<int>(v.integer));
        if (ev == nullptr) return fail(("a value of " + f->enum_type()->full_name()).c_str());
        add_to_list ? r->AddEnum(m, f, ev) : r->SetEnum(m, f, ev);
        return Value{};
      }
      case FieldDescriptor::CPPTYPE_STRING:
        if (v.type != Value::Type::kString && v.type != Value::Type::kSymbol)
          return fail("a string");
        add_to_list ? r->AddString(m, f, std::string(v.text))
                    : r->SetString(m, f, std::string(v.text));
        return Value{};
      case FieldDescriptor::CPPTYPE_MESSAGE: {
        if (v.type != Value::Type::kAddress) return fail("a message");
        auto it = entries_.find(v.address);
        if (it == entries_.end()) return fail("a live message");
        const Message& src = *it->second.message;
        if (src.GetDescriptor() != f->message_type())
          return fail(f->message_type()->full_name().c_str());
        Message* to = add_to_list ? r->AddMessage(m, f) : r->MutableMessage(m, f);
        if (to != &src) to->CopyFrom(src);  // the field set from its own view: nothing to do
        return Value{};
      }
    }
    return Value{};
  }

  HostState& s_;
  Template msg_;
  int slot_type_ = 0, slot_comp_ = 0, slot_msg_type_ = 0, slot_from_ = 0, slot_at_ = 0,
      slot_client_id_ = 0, slot_ptr_ = 0;
  std::vector<Value> values_;
  std::vector<FactHandle> facts_;
  // The message types some rule can match (std::nullopt: any), for Environment::code_version()
  // code_version_ (0: not yet).
  std::optional<TypeNames> matched_;
  std::vector<std::pair<const Descriptor*, bool>> wanted_;  // wanted()'s answers so far
  std::uint64_t code_version_ = 0;
  std::unordered_map<const void*, Entry> entries_;
  std::vector<const void*> transient_;  // keys of the kReceived and kView entries of this run
  std::unordered_map<std::string, const Message*> by_name_;
  struct FieldCacheEntry {
    const Descriptor* descriptor = nullptr;
    const char* name = nullptr;
    const FieldDescriptor* field = nullptr;
  };
  static constexpr std::size_t kFieldCacheSize = 64;
  std::array<FieldCacheEntry, kFieldCacheSize> field_cache_{};
  int nested_types_ = 0;  // entries of by_name_ that are not registry types
  // pb-unchanged: the last message per key, as serialised bytes.
  struct Last {
    const Descriptor* type = nullptr;
    std::string bytes;
  };
  static constexpr std::size_t kMaxUnchangedKeys = 1024;
  std::unordered_map<std::string, Last> last_;
  std::unordered_map<const Descriptor*, std::unique_ptr<Message>> scratch_;
  std::vector<const FieldDescriptor*> fields_scratch_;
  std::string key_scratch_, bytes_scratch_;
  std::vector<std::int64_t> clients_;  // pb-connect's open connections
  std::int64_t server_port_ = 0;       // pb-server-enable's port (0: none)
  std::int64_t last_client_ = 0;
};

}  // namespace

std::unique_ptr<Feature> make_protobuf_feature(HostState& s) {
  return std::make_unique<ProtobufFeature>(s);
}

}  // namespace llsf::clips::detail
