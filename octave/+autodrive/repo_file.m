function p = repo_file(varargin)
  % AUTODRIVE.REPO_FILE  A file of the repository this toolbox lives in (octave/+autodrive/ is
  % two levels down), e.g. autodrive.repo_file('lcm_types', 'channels.yaml').
  here = fileparts(mfilename('fullpath'));
  p = fullfile(fileparts(fileparts(here)), varargin{:});
end
