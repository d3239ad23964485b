// An independent Foxglove WebSocket client for labstand's live-view tests: the
// @foxglove/ws-protocol package's FoxgloveClient over the `ws` package.
//
//   node client.js URL [--stall SECONDS] [--latency]
//
// Subscribes to every advertised channel. Normally it reads until the server closes the
// connection, then prints one JSON line: the negotiated subprotocol, the server's name,
// and per topic the message count, the log times and, for JSON topics, the decoded
// messages' `seq` and `t_ns`, the last message, and the largest magnitude of each
// numeric field (`maxAbs`). With --stall it subscribes, then stops reading from its
// socket (a viewer that hangs) for SECONDS, and exits. With --latency it also reports
// the wall time each message arrived (ns, `recvNs`), for benchmarks/bench_live.py.
"use strict";
const { FoxgloveClient } = require("@foxglove/ws-protocol");
const WebSocket = require("ws");

const url = process.argv[2];
const stallAt = process.argv.indexOf("--stall");
const stallS = stallAt > 0 ? Number(process.argv[stallAt + 1]) : 0;
const latency = process.argv.includes("--latency");
const decoder = new TextDecoder();
const { performance } = require("perf_hooks");

function connect(deadline) {
  // Offer both: ws-protocol 0.8 speaks foxglove.websocket.v1, foxglove-sdk servers
  // foxglove.sdk.v1; the app offers both too.
  const ws = new WebSocket(url, ["foxglove.sdk.v1", FoxgloveClient.SUPPORTED_SUBPROTOCOL]);
  ws.on("error", (err) => {
    if (Date.now() < deadline && err.code === "ECONNREFUSED") {
      setTimeout(() => connect(deadline), 100);
    } else {
      console.error(`client: ${err.message}`);
      process.exit(1);
    }
  });
  ws.on("open", () => run(ws));
}

function run(ws) {
  const client = new FoxgloveClient({ ws });
  const topics = {}; // topic -> {count, logTimes, seq, tNs}
  const bySubscription = new Map();
  let serverName = "";
  client.on("serverInfo", (info) => {
    serverName = info.name;
  });
  client.on("advertise", (channels) => {
    for (const channel of channels) {
      const id = client.subscribe(channel.id);
      bySubscription.set(id, channel);
      topics[channel.topic] = {
        encoding: channel.encoding,
        schemaName: channel.schemaName,
        count: 0,
        logTimes: [],
        seq: [],
        tNs: [],
        last: null,
        recvNs: [],
        maxAbs: {},
      };
    }
    if (stallS > 0) {
      setTimeout(() => {
        ws._socket.pause(); // connected, subscribed, never reading again
        setTimeout(() => process.exit(0), stallS * 1000);
        console.log(JSON.stringify({ stalled: true, protocol: ws.protocol }));
      }, 200);
    }
  });
  client.on("message", ({ subscriptionId, timestamp, data }) => {
    const channel = bySubscription.get(subscriptionId);
    const topic = topics[channel.topic];
    topic.count += 1;
    topic.logTimes.push(timestamp.toString());
    if (latency) topic.recvNs.push(Math.round((performance.timeOrigin + performance.now()) * 1e6));
    if (channel.encoding === "json") {
      const msg = JSON.parse(decoder.decode(data));
      if (msg.seq !== undefined) topic.seq.push(msg.seq);
      if (msg.t_ns !== undefined) topic.tNs.push(msg.t_ns);
      topic.last = msg;
      for (const [key, value] of Object.entries(msg)) {
        if (typeof value === "number") {
          topic.maxAbs[key] = Math.max(topic.maxAbs[key] ?? 0, Math.abs(value));
        }
      }
    }
  });
  client.on("close", () => {
    // exit once the pipe took everything (process.exit alone truncates a piped stdout)
    const report = JSON.stringify({ protocol: ws.protocol, server: serverName, topics });
    process.stdout.write(report + "\n", () => process.exit(0));
  });
}

connect(Date.now() + 30000);
