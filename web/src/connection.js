// The page's link to partsim: HTTP for the scene's content, a rosbridge v2 WebSocket (roslib)
// for poses, joint states, status and the services of docs/viewer.md.
import { Ros, Topic, Service } from 'roslib';

export class Connection {
  constructor(token) {
    this.token = token;
    this.ros = null;
    this.connected = false;
    this.listeners = { close: [], error: [] };
  }

  /** URL of an HTTP API path with the token. */
  apiUrl(path) {
    const sep = path.includes('?') ? '&' : '?';
    return this.token ? `${path}${sep}token=${encodeURIComponent(this.token)}` : path;
  }

  async fetchJson(path) {
    const r = await fetch(this.apiUrl(path), { cache: 'no-store' });
    if (!r.ok) throw new Error(`${path}: HTTP ${r.status}`);
    return r.json();
  }

  async fetchBuffer(path) {
    const r = await fetch(this.apiUrl(path));
    if (!r.ok) throw new Error(`${path}: HTTP ${r.status}`);
    return r.arrayBuffer();
  }

  async fetchBlob(path) {
    const r = await fetch(this.apiUrl(path));
    if (!r.ok) throw new Error(`${path}: HTTP ${r.status}`);
    return r.blob();
  }

  /** Opens the WebSocket on the page's own host and port; the auth op goes first. */
  connect() {
    const scheme = location.protocol === 'https:' ? 'wss://' : 'ws://';
    this.ros = new Ros();
    // queued before any subscription, so it is the first op the server reads
    this.ros.callOnConnection({ op: 'auth', mac: this.token });
    return new Promise((resolve, reject) => {
      this.ros.once('connection', () => {
        this.connected = true;
        resolve();
      });
      this.ros.on('close', () => {
        const was = this.connected;
        this.connected = false;
        for (const f of this.listeners.close) f(was);
      });
      this.ros.on('error', (e) => {
        for (const f of this.listeners.error) f(e);
        if (!this.connected) reject(new Error('WebSocket connection failed'));
      });
      this.ros.connect(scheme + location.host).catch(reject);
    });
  }

  on(event, f) {
    this.listeners[event].push(f);
  }

  /** Subscribes to a topic; returns a function that unsubscribes. */
  subscribe(name, messageType, callback) {
    const topic = new Topic({ ros: this.ros, name, messageType });
    topic.subscribe(callback);
    return () => topic.unsubscribe(callback);
  }

  /** Calls a service; resolves with its values, rejects with the server's message. */
  call(name, args = {}, timeoutMs = 10000) {
    const service = new Service({ ros: this.ros, name, serviceType: '' });
    return new Promise((resolve, reject) => {
      const timer = setTimeout(() => reject(new Error(`${name}: no answer in ${timeoutMs} ms`)), timeoutMs);
      service.callService(
        args,
        (values) => {
          clearTimeout(timer);
          if (values && values.success === false) reject(new Error(`${name}: ${values.message || 'failed'}`));
          else resolve(values || {});
        },
        (error) => {
          clearTimeout(timer);
          const text = typeof error === 'string' ? error : JSON.stringify(error);
          reject(new Error(`${name}: ${text}`));
        },
      );
    });
  }
}
