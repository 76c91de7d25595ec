// Stands in for Node's 'ws' package in the browser bundle: roslib imports it only where there is
// no WebSocket of the platform's own, which never happens in a browser.
export class WebSocket {
  constructor() {
    throw new Error('the viewer page uses the browser\'s WebSocket');
  }
}
export default { WebSocket };
