// An independent reader of horus's MCAP files, made of Foxglove's own libraries: @mcap/core reads
// the container (through its summary and chunk indexes, CRCs checked), @foxglove/omgidl-parser
// parses each channel's schema, @foxglove/omgidl-serialization decodes each message's CDR.
//
//   node read_mcap.mjs FILE.mcap
//
// Prints one JSON object per line: {"schema": ...} per schema, then {"topic", "schema",
// "sequence", "log_time", "publish_time", "value"} per message (64-bit integers as decimal
// strings, typed arrays as arrays, non-finite floats as null), then {"summary": ...}. Exits 1
// with {"error": ...} on the first thing it cannot read.
import { readFile } from "node:fs/promises";
import { McapIndexedReader, McapStreamReader } from "@mcap/core";
import { parseIDL } from "@foxglove/omgidl-parser";
import { MessageReader } from "@foxglove/omgidl-serialization";
import * as zstd from "@foxglove/wasm-zstd";
import lz4 from "@foxglove/wasm-lz4";
import { crc32 } from "@foxglove/crc";
import { plain } from "../js_common/plain.mjs";

function fail(what) {
  console.log(JSON.stringify({ error: what }));
  process.exit(1);
}

const file = process.argv[2];
if (!file) fail("usage: node read_mcap.mjs FILE.mcap");
const bytes = new Uint8Array(await readFile(file));
await zstd.isLoaded;
await lz4.isLoaded;
const decompressHandlers = {
  zstd: (data, size) => zstd.decompress(data, Number(size)),
  lz4: (data, size) => lz4(data, Number(size)),
};

try {
  // 1. Through the summary: the index a seeking reader (Foxglove) uses.
  const readable = {
    size: async () => BigInt(bytes.length),
    read: async (offset, length) => bytes.subarray(Number(offset), Number(offset + length)),
  };
  const indexed = await McapIndexedReader.Initialize({ readable, decompressHandlers });
  if (indexed.dataSectionCrc !== undefined && indexed.dataSectionCrc !== 0) {
    const crc = crc32(bytes.subarray(0, Number(indexed.dataEndOffset)));
    if (crc !== indexed.dataSectionCrc)
      fail(`the data section's CRC is ${indexed.dataSectionCrc}, the bytes give ${crc}`);
  }
  const readers = new Map();
  for (const [id, schema] of indexed.schemasById) {
    if (schema.encoding !== "omgidl") fail(`schema ${schema.name} has encoding ${schema.encoding}, not omgidl`);
    const text = new TextDecoder().decode(schema.data);
    const definitions = parseIDL(text);
    readers.set(id, new MessageReader(schema.name, definitions));
    console.log(JSON.stringify({ schema: schema.name, definitions: definitions.length }));
  }
  let count = 0;
  for await (const m of indexed.readMessages({ validateCrcs: true })) {
    const channel = indexed.channelsById.get(m.channelId);
    if (channel.messageEncoding !== "cdr") fail(`channel ${channel.topic} has message encoding ${channel.messageEncoding}`);
    const reader = readers.get(channel.schemaId);
    if (!reader) fail(`channel ${channel.topic} has no schema`);
    const value = reader.readMessage(m.data);
    console.log(JSON.stringify({
      topic: channel.topic,
      schema: indexed.schemasById.get(channel.schemaId).name,
      sequence: m.sequence,
      log_time: m.logTime.toString(),
      publish_time: m.publishTime.toString(),
      metadata: Object.fromEntries(channel.metadata),
      value: plain(value),
    }));
    ++count;
  }
  // 2. Front to back, every record, CRCs checked: what a streaming reader sees.
  const stream = new McapStreamReader({ decompressHandlers, validateCrcs: true });
  stream.append(bytes);
  let streamed = 0;
  let footer = false;
  for (let r; (r = stream.nextRecord()); ) {
    if (r.type === "Message") ++streamed;
    if (r.type === "Footer") footer = true;
  }
  if (!stream.done() || !footer) fail("the stream reader did not reach the footer and the closing magic");
  if (streamed !== count) fail(`the stream reader read ${streamed} messages, the indexed reader ${count}`);
  const stats = indexed.statistics;
  console.log(JSON.stringify({
    summary: {
      messages: count,
      statistics_messages: stats ? stats.messageCount.toString() : null,
      channels: indexed.channelsById.size,
      schemas: indexed.schemasById.size,
      chunks: indexed.chunkIndexes.length,
      library: indexed.header.library,
    },
  }));
} catch (e) {
  fail(String(e && e.stack ? e.stack : e));
}
