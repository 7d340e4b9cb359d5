function p = default_key_path(vehicle)
  % AUTODRIVE.DEFAULT_KEY_PATH  $AUTODRIVE_KEY_DIR/<VEH>.key, else
  % $XDG_CONFIG_HOME (or ~/.config)/autodrive/keys/<VEH>.key, as the other signers.
  d = getenv('AUTODRIVE_KEY_DIR');
  if isempty(d)
    base = getenv('XDG_CONFIG_HOME');
    if isempty(base)
      base = fullfile(getenv('HOME'), '.config');
    end
    d = fullfile(base, 'autodrive', 'keys');
  end
  p = fullfile(d, [vehicle '.key']);
end
