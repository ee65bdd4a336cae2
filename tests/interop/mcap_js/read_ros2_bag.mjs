// An independent reader of horus's ROS 2 bags (`horus record --profile ros2`), made of Foxglove's
// own ROS 2 libraries: @mcap/core reads the container, @foxglove/rosmsg parses each channel's
// ros2msg schema, @foxglove/rosmsg2-serialization decodes each message's CDR as a ROS 2 node's.
//
//   node read_ros2_bag.mjs FILE.mcap     one JSON object per line: {"profile"}, {"schema", "types"}
//                                        per schema, {"topic", "type", "metadata", "value"} per
//                                        message, {"metadata": name, "values"} per Metadata record,
//                                        then {"summary"}
//   node read_ros2_bag.mjs --hash DIR    parses every DIR/msg/*.msg of a ROS 2 interface package
//                                        (`horus idl --ros2`) and prints {"type", "hash"}: its
//                                        RIHS01 type hash computed here from rosmsg's parse, as
//                                        rosidl defines it (REP-2011)
//
// Exits 1 with {"error": ...} on the first thing it cannot read.
import { readFile, readdir } from "node:fs/promises";
import { createHash } from "node:crypto";
import { McapIndexedReader } from "@mcap/core";
import { parse } from "@foxglove/rosmsg";
import { MessageReader } from "@foxglove/rosmsg2-serialization";
import * as zstd from "@foxglove/wasm-zstd";
import lz4 from "@foxglove/wasm-lz4";
import { plain } from "../js_common/plain.mjs";

function fail(what) {
  console.log(JSON.stringify({ error: what }));
  process.exit(1);
}

async function readBag(file) {
  const bytes = new Uint8Array(await readFile(file));
  await zstd.isLoaded;
  await lz4.isLoaded;
  const readable = {
    size: async () => BigInt(bytes.length),
    read: async (offset, length) => bytes.subarray(Number(offset), Number(offset + length)),
  };
  const reader = await McapIndexedReader.Initialize({
    readable,
    decompressHandlers: {
      zstd: (data, size) => zstd.decompress(data, Number(size)),
      lz4: (data, size) => lz4(data, Number(size)),
    },
  });
  console.log(JSON.stringify({ profile: reader.header.profile }));
  const readers = new Map();
  for (const [id, schema] of reader.schemasById) {
    if (schema.encoding !== "ros2msg") fail(`schema ${schema.name} has encoding ${schema.encoding}, not ros2msg`);
    const definitions = parse(new TextDecoder().decode(schema.data), { ros2: true });
    readers.set(id, new MessageReader(definitions));
    console.log(JSON.stringify({ schema: schema.name, types: definitions.length }));
  }
  let count = 0;
  for await (const m of reader.readMessages({ validateCrcs: true })) {
    const channel = reader.channelsById.get(m.channelId);
    if (channel.messageEncoding !== "cdr") fail(`channel ${channel.topic} has message encoding ${channel.messageEncoding}`);
    const decoder = readers.get(channel.schemaId);
    if (!decoder) fail(`channel ${channel.topic} has no schema`);
    let value;
    try {
      value = decoder.readMessage(m.data);
    } catch (e) {
      fail(`channel ${channel.topic}: message ${m.sequence} does not decode: ${e.message}`);
    }
    console.log(JSON.stringify({
      topic: channel.topic,
      type: reader.schemasById.get(channel.schemaId).name,
      metadata: Object.fromEntries(channel.metadata),
      value: plain(value),
    }));
    ++count;
  }
  for (const index of reader.metadataIndexes) {
    for await (const record of reader.readMetadata({ name: index.name })) {
      console.log(JSON.stringify({ metadata: record.name, values: Object.fromEntries(record.metadata) }));
    }
  }
  console.log(JSON.stringify({ summary: { messages: count, channels: reader.channelsById.size } }));
}

// -- RIHS01 (REP-2011): type_description_interfaces' field type ids --------------------------

const BASE_IDS = {
  int8: 2, uint8: 3, int16: 4, uint16: 5, int32: 6, uint32: 7, int64: 8, uint64: 9,
  float32: 10, float64: 11, char: 3, bool: 15, byte: 16, string: 17, wstring: 18,
};

function fieldType(field, pkg) {
  let nested = "";
  let base;
  let stringCapacity = 0;
  if (field.isComplex) {
    base = 1;
    const [p, n] = field.type.includes("/") ? [field.type.split("/")[0], field.type.split("/").pop()] : [pkg, field.type];
    nested = `${p}/msg/${n}`;
  } else if ((field.type === "string" || field.type === "wstring") && field.upperBound !== undefined) {
    base = field.type === "string" ? 21 : 22;
    stringCapacity = field.upperBound;
  } else {
    base = BASE_IDS[field.type];
    if (base === undefined) fail(`field ${field.name}: type ${field.type} has no type id`);
  }
  let id = base;
  let capacity = 0;
  if (field.isArray) {
    if (field.arrayLength !== undefined) {
      id += 48;
      capacity = field.arrayLength;
    } else if (field.arrayUpperBound !== undefined) {
      id += 96;
      capacity = field.arrayUpperBound;
    } else {
      id += 144;
    }
  }
  return { type_id: id, capacity, string_capacity: stringCapacity, nested_type_name: nested };
}

// Python's json.dumps with its default separators, which rosidl hashes.
function pyJson(v) {
  if (Array.isArray(v)) return `[${v.map(pyJson).join(", ")}]`;
  if (v !== null && typeof v === "object")
    return `{${Object.entries(v).map(([k, x]) => `${JSON.stringify(k)}: ${pyJson(x)}`).join(", ")}}`;
  return JSON.stringify(v);
}

async function hashPackage(dir) {
  const pkg = dir.replace(/\/+$/, "").split("/").pop();
  const types = new Map();
  for (const file of (await readdir(`${dir}/msg`)).filter((f) => f.endsWith(".msg")).sort()) {
    const name = `${pkg}/msg/${file.slice(0, -4)}`;
    const [root] = parse(await readFile(`${dir}/msg/${file}`, "utf8"), { ros2: true, skipTypeFixup: true });
    const fields = root.definitions.filter((f) => !f.isConstant).map((f) => ({ name: f.name, type: fieldType(f, pkg) }));
    types.set(name, { type_name: name, fields });
  }
  for (const name of types.keys()) {
    const refs = new Set();
    const visit = (t) => {
      for (const f of types.get(t).fields) {
        const n = f.type.nested_type_name;
        if (n === "" || refs.has(n)) continue;
        if (!types.has(n)) fail(`${t}: ${n} is not in package ${pkg}`);
        refs.add(n);
        visit(n);
      }
    };
    visit(name);
    const description = {
      type_description: types.get(name),
      referenced_type_descriptions: [...refs].sort().map((r) => types.get(r)),
    };
    const hash = createHash("sha256").update(pyJson(description)).digest("hex");
    console.log(JSON.stringify({ type: name, hash: `RIHS01_${hash}` }));
  }
}

try {
  if (process.argv[2] === "--hash" && process.argv[3]) await hashPackage(process.argv[3]);
  else if (process.argv[2]) await readBag(process.argv[2]);
  else fail("usage: node read_ros2_bag.mjs FILE.mcap | --hash DIR");
} catch (e) {
  fail(e.stack ?? String(e));
}
